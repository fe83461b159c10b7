// CHOLMOD's supernodal factorization runs its dense blocks through BLAS. The Debian OpenBLAS
// (pthreads) starts one thread per core, and on these problems (a few thousand to tens of
// thousands of tetrahedra, small supernodes) its threads spend their time waiting on each
// other (sched_yield in exec_blas_async_wait), taking the cores from the solver's own OpenMP
// loops. One BLAS thread against two, medians: 1.41 and 1.54 times as fast (two runs) on a
// stiffness search on the 300 Pa phantom, 1.07 on a balanced and 1.20 on an accurate
// registration of the phantom (BENCHMARKS.md, "The stiffness search at the soft end").
#pragma once

namespace btr {

/// Sets OpenBLAS to one thread, once per process (every CHOLMOD solver calls it when built).
/// An explicit OPENBLAS_NUM_THREADS in the environment is left to rule, and a BLAS other than
/// OpenBLAS is left as it is. Returns whether the setting was applied.
bool use_single_threaded_blas();

}  // namespace btr
