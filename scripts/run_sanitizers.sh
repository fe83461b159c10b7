#!/usr/bin/env bash
# Builds the package with AddressSanitizer and UndefinedBehaviorSanitizer in its own workspace
# (build/asan_ws) and runs every test under them: the core and converter unit tests and the
# node's rostests. Any sanitizer report fails the run. About 15 to 25 minutes on 2 cores.
# Usage: bash scripts/run_sanitizers.sh      (ends with "N passed, N failed", like run_tests.sh)
set -uo pipefail
REPO_ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
export BTR_WS="$REPO_ROOT/build/asan_ws" BTR_BUILD_TYPE=RelWithDebInfo
FLAGS="-fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=undefined"
bash "$REPO_ROOT/scripts/setup.sh" -DCMAKE_CXX_FLAGS="$FLAGS" -DCMAKE_EXE_LINKER_FLAGS="-fsanitize=address,undefined" \
  -DCMAKE_SHARED_LINKER_FLAGS="-fsanitize=address,undefined" || { echo "build failed"; echo "0 passed, 1 failed"; exit 1; }
# ROS's own libraries are not instrumented and keep some memory until exit: leaks are not
# what this run looks for. Any other report aborts the process, which fails its test.
export ASAN_OPTIONS="detect_leaks=0:abort_on_error=1:halt_on_error=1" UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
export PATH="/usr/bin:$PATH"
cd "$BTR_WS"
rm -rf build/test_results
catkin_make -j"${BTR_JOBS:-$(nproc)}" -DPYTHON_EXECUTABLE=/usr/bin/python3 run_tests > "$BTR_WS/run_tests.log" 2>&1
build_rc=$?
grep -E "ERROR: AddressSanitizer|runtime error:|SUMMARY: (Address|UndefinedBehavior)Sanitizer" "$BTR_WS/run_tests.log" | head -20
summary="$(catkin_test_results build/test_results 2>&1)"
results_rc=$?
echo "$summary" | tail -n 5
read -r total failed < <(/usr/bin/python3 - build/test_results <<'PY'
import sys, glob, os
import xml.etree.ElementTree as ET
total = failed = 0
for path in glob.glob(os.path.join(sys.argv[1], '**', '*.xml'), recursive=True):
    try:
        root = ET.parse(path).getroot()
    except ET.ParseError:
        failed += 1; total += 1; continue
    for case in (root.iter('testcase')):
        total += 1
        failed += case.find('failure') is not None or case.find('error') is not None
print(total, failed)
PY
)
sanitizer_reports=$(grep -cE "ERROR: AddressSanitizer|runtime error:" "$BTR_WS/run_tests.log")
if [ "$build_rc" -ne 0 ] || [ "$results_rc" -ne 0 ] || [ "$total" -eq 0 ] || [ "$sanitizer_reports" -ne 0 ]; then
  [ "$failed" -eq 0 ] && failed=1
  echo "$((total - failed)) passed, $failed failed"
  exit 1
fi
echo "$((total - failed)) passed, $failed failed"
