#include "breast_tumour_registration/fem/heap_retention.h"

#include <cstdlib>
#include <cstring>
#include <mutex>

#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace btr {

bool keep_freed_heap_memory() {
  static std::once_flag once;
  static bool applied = false;
  std::call_once(once, [] {
#if defined(__GLIBC__)
    const char* tunables = std::getenv("GLIBC_TUNABLES");
    if ((tunables && std::strstr(tunables, "glibc.malloc.")) || std::getenv("MALLOC_MMAP_THRESHOLD_") ||
        std::getenv("MALLOC_TRIM_THRESHOLD_"))
      return;  // the user's choice
    // Both calls succeed or neither matters: a threshold mallopt refuses leaves glibc's default.
    applied = mallopt(M_MMAP_THRESHOLD, 32 * 1024 * 1024) == 1;
    applied = mallopt(M_TRIM_THRESHOLD, 512 * 1024 * 1024) == 1 && applied;
#endif
  });
  return applied;
}

}  // namespace btr
