#!/usr/bin/env bash
# Builds the libFuzzer harnesses (test/fuzz, clang + ASan + UBSan) into build/fuzz and runs
# each target for SECONDS (default 30) on its committed seed corpus. New inputs go to
# build/fuzz/corpus/<target> (the committed corpus stays small); a crash, a sanitizer report,
# an exception outside the InputError contract, a 10 s input or 2 GB of memory fails the
# target, and libFuzzer writes the input to build/fuzz/artifacts/ (commit it to
# test/fuzz/corpus/<target>/ with the fix, so that it stays a regression input).
# Usage: run_fuzz.sh [SECONDS] [JUNIT_XML]. Ends with "N passed, N failed".
set -uo pipefail
REPO_ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
SECONDS_EACH="${1:-30}"
JUNIT="${2:-}"
BUILD="$REPO_ROOT/build/fuzz"
export PATH="/usr/bin:$PATH"
TARGETS=(fuzz_surface fuzz_tet_mesh fuzz_index fuzz_scene fuzz_model fuzz_pointcloud2 fuzz_markups fuzz_label_volume fuzz_truth)

mkdir -p "$BUILD/artifacts"
if ! { cmake -S "$REPO_ROOT/test/fuzz" -B "$BUILD" -DCMAKE_CXX_COMPILER=clang++ -DCMAKE_BUILD_TYPE=None >"$BUILD/configure.log" 2>&1 &&
       cmake --build "$BUILD" -j"${BTR_JOBS:-$(nproc)}" >"$BUILD/build.log" 2>&1; }; then
  tail -n 30 "$BUILD/configure.log" "$BUILD/build.log"
  echo "fuzz build failed"
  echo "0 passed, 1 failed"
  exit 1
fi

passed=0; failed=0; cases=""
for t in "${TARGETS[@]}"; do
  work="$BUILD/corpus/$t"
  mkdir -p "$work"
  # detect_leaks=0: yaml-cpp and CGAL keep static caches; leaks are not what this looks for.
  if ASAN_OPTIONS="detect_leaks=0:abort_on_error=1" UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1" \
     "$BUILD/$t" "$work" "$REPO_ROOT/test/fuzz/corpus/$t" -max_total_time="$SECONDS_EACH" -timeout=10 -rss_limit_mb=2048 \
       -artifact_prefix="$BUILD/artifacts/$t-" -print_final_stats=1 >"$BUILD/$t.log" 2>&1; then
    runs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$BUILD/$t.log" | grep -o '[0-9]*$')
    echo "[fuzz] $t: no finding in ${SECONDS_EACH} s (${runs:-?} inputs)"
    passed=$((passed + 1))
    cases+="  <testcase classname=\"fuzz\" name=\"$t\" time=\"$SECONDS_EACH\"/>"$'\n'
  else
    echo "[fuzz] $t: FINDING (log: $BUILD/$t.log)"
    grep -m 5 -E 'ERROR|SUMMARY|fuzz:|Test unit written' "$BUILD/$t.log"
    failed=$((failed + 1))
    cases+="  <testcase classname=\"fuzz\" name=\"$t\" time=\"$SECONDS_EACH\"><failure message=\"finding, see $BUILD/$t.log\"/></testcase>"$'\n'
  fi
done
if [ -n "$JUNIT" ]; then
  mkdir -p "$(dirname "$JUNIT")"
  printf '<?xml version="1.0" encoding="UTF-8"?>\n<testsuite name="fuzz" tests="%d" failures="%d" errors="0">\n%s</testsuite>\n' \
    "$((passed + failed))" "$failed" "$cases" >"$JUNIT"
fi
echo "$passed passed, $failed failed"
[ "$failed" -eq 0 ]
