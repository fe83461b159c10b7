#!/usr/bin/env bash
# The README's test command again, in its own workspace (build/asan_ws) built with
# AddressSanitizer and UndefinedBehaviorSanitizer: the core and converter unit tests and the
# node's rostests. A sanitizer report aborts the process, which fails its test. About 20 to
# 30 minutes on 2 cores. Ends with "N passed, N failed", like run_tests.sh.
set -uo pipefail
REPO_ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
FLAGS="-fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=undefined"
export BTR_WS="$REPO_ROOT/build/asan_ws" BTR_BUILD_TYPE=RelWithDebInfo BTR_FUZZ_SECONDS=0  # the fuzzers ran in run_tests.sh
export BTR_CMAKE_ARGS="-DCMAKE_CXX_FLAGS=$FLAGS|-DCMAKE_EXE_LINKER_FLAGS=-fsanitize=address,undefined|-DCMAKE_SHARED_LINKER_FLAGS=-fsanitize=address,undefined"
# detect_leaks=0: ROS's own (uninstrumented) libraries keep memory until exit; leaks are not
# what this run looks for. alloc_dealloc_mismatch=0: libpcl_registration (Debian's build, not
# ours) frees with operator delete what Eigen's aligned allocator took with malloc, inside
# CorrespondenceRejectorMedianDistance::setSourcePoints; reported once, it is not our code.
export ASAN_OPTIONS="detect_leaks=0:alloc_dealloc_mismatch=0:abort_on_error=1:halt_on_error=1"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
exec bash "$REPO_ROOT/scripts/run_tests.sh"
