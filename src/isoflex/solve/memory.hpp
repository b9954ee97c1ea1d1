#pragma once
// Process-wide allocator setting for programs that factorize large sparse matrices again and
// again (a Newton iteration per step): glibc serves blocks above 128 kB–32 MB by mmap and returns
// freed heap top to the system, so the factors, fronts and sparse temporaries of every
// iteration are faulted in anew (≈ 20 % of a shell_bench step at N = 70 was kernel page-fault
// time, bench/shells.md). retain_freed_memory() makes malloc keep freed memory for reuse (no
// mmap, no trimming). Call it once at the start of main(); the library never calls it.
#include <optional>

namespace isoflex::solve {

void retain_freed_memory();

// The memory the system can give a new process without swapping: MemAvailable of /proc/meminfo
// (Linux ≥ 3.14, proc(5): "an estimate of how much memory is available for starting new
// applications, without swapping"), in bytes; nullopt where it cannot be read.
std::optional<double> available_memory_bytes();

}  // namespace isoflex::solve
