#include "isoflex/solve/memory.hpp"

#include <malloc.h>

namespace isoflex::solve {

void retain_freed_memory() {
  mallopt(M_MMAP_MAX, 0);
  mallopt(M_TRIM_THRESHOLD, -1);  // the largest value: never trim
  mallopt(M_TOP_PAD, 64 << 20);   // grow the heap in steps of 64 MB
}

}  // namespace isoflex::solve
