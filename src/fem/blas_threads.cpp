#include "breast_tumour_registration/fem/blas_threads.h"

#include <dlfcn.h>

#include <cstdlib>
#include <mutex>

namespace btr {

bool use_single_threaded_blas() {
  static std::once_flag once;
  static bool applied = false;
  std::call_once(once, [] {
    if (std::getenv("OPENBLAS_NUM_THREADS")) return;  // the user's choice
    // Looked up at run time: the BLAS is whatever libblas.so.3 the system's alternatives chose.
    using SetThreads = void (*)(int);
    auto set = reinterpret_cast<SetThreads>(dlsym(RTLD_DEFAULT, "openblas_set_num_threads"));
    if (!set) return;
    set(1);
    applied = true;
  });
  return applied;
}

}  // namespace btr
