// An OpenMP loop whose body may throw. An exception must not leave an OpenMP region (it would
// terminate the program), so each iteration's is caught and the first one returned, for the
// caller to clean up and rethrow.
#pragma once

#include <exception>

namespace btr {

/// Runs body(i) for i in [0, n) on OpenMP threads (dynamic chunks of 64). Returns the first
/// exception a body threw (null: none); the other iterations still ran.
template <class Index, class Body>
std::exception_ptr parallel_for_capturing(Index n, Body&& body) {
  std::exception_ptr failed;
#pragma omp parallel for schedule(dynamic, 64)
  for (Index i = 0; i < n; ++i) {
    try {
      body(i);
    } catch (...) {
#pragma omp critical(btr_parallel_for_capturing)
      if (!failed) failed = std::current_exception();
    }
  }
  return failed;
}

}  // namespace btr
