// A registration factorizes and assembles the same sizes of matrix again and again (every
// Newton iteration, every candidate of the stiffness search). glibc hands blocks above its mmap
// threshold back to the system when freed and trims the heap's top above 128 kB, so each new
// factorization's workspace (CHOLMOD's transposed copy, its supernodes) and each assembler's
// arrays are page-faulted in afresh: 12 % of a nodal-form registration's samples were in the
// kernel's page-fault handler. Keeping freed memory in the process (mmap threshold 32 MB,
// glibc's maximum; trim threshold 512 MB) made single registrations 4 to 23 % faster on SfePy's
// bodies for 5 to 17 MB more peak memory (BENCHMARKS.md, "The stiffness search and the heap").
#pragma once

namespace btr {

/// Keeps freed heap memory in the process, once per process (every CHOLMOD solver calls it when
/// built, as use_single_threaded_blas). A malloc setting in the environment (GLIBC_TUNABLES
/// naming glibc.malloc, or MALLOC_MMAP_THRESHOLD_ / MALLOC_TRIM_THRESHOLD_) is left to rule,
/// and an allocator other than glibc's is left as it is. Returns whether it was applied.
bool keep_freed_heap_memory();

}  // namespace btr
