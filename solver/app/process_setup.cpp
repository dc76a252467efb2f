#include "process_setup.hpp"

#include <cstdlib>
#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace basalt::run {

void bound_heap_growth() {
#if defined(__GLIBC__)
  constexpr int kBytes = 1 << 20;
  if (!std::getenv("MALLOC_MMAP_THRESHOLD_")) mallopt(M_MMAP_THRESHOLD, kBytes);
  if (!std::getenv("MALLOC_TRIM_THRESHOLD_")) mallopt(M_TRIM_THRESHOLD, kBytes);
#endif
}

void prefer_eager_shared_memory_messages() {
  setenv("OMPI_MCA_btl_vader_eager_limit", "65536", 0);
  setenv("OMPI_MCA_btl_vader_max_send_size", "65536", 0);
}

}  // namespace basalt::run
