#include "isoflex/solve/memory.hpp"

#include <malloc.h>

#include <fstream>
#include <sstream>
#include <string>

namespace isoflex::solve {

void retain_freed_memory() {
  mallopt(M_MMAP_MAX, 0);
  mallopt(M_TRIM_THRESHOLD, -1);  // the largest value: never trim
  mallopt(M_TOP_PAD, 64 << 20);   // grow the heap in steps of 64 MB
}

std::optional<double> available_memory_bytes() {
  std::ifstream in("/proc/meminfo");
  std::string line;
  while (std::getline(in, line)) {
    std::istringstream fields(line);
    std::string key, unit;
    double value = 0;
    if (fields >> key >> value >> unit && key == "MemAvailable:" && unit == "kB")
      return value * 1024.0;
  }
  return std::nullopt;
}

}  // namespace isoflex::solve
