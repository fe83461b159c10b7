#!/usr/bin/env bash
# The README's test command: installs what is missing, builds, runs every test
# (gtest unit tests, rostest integration tests and a bounded run of every fuzz target) and
# fails when any test fails.
# Ends with the line "N passed, N failed".
set -uo pipefail
REPO_ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
bash "$REPO_ROOT/scripts/setup.sh" || { echo "build failed"; echo "0 passed, 1 failed"; exit 1; }

WS="${BTR_WS:-$REPO_ROOT/build/ws}"
export PATH="/usr/bin:$PATH"
cd "$WS"
rm -rf build/test_results
# run_tests exits 0 even when tests fail; catkin_test_results below is the verdict.
catkin_make -j"${BTR_JOBS:-$(nproc)}" -DPYTHON_EXECUTABLE=/usr/bin/python3 run_tests
build_rc=$?

# The fuzz targets (test/fuzz), each for a bounded time; their JUnit file joins the others.
# BTR_FUZZ_SECONDS=0 skips them (the sanitizer workspace, which runs the same tests again).
# A fuzz build that fails writes no JUnit file, so its failure is counted here.
fuzz_rc=0
if [ "${BTR_FUZZ_SECONDS:-30}" -gt 0 ]; then
  bash "$REPO_ROOT/scripts/run_fuzz.sh" "${BTR_FUZZ_SECONDS:-30}" "$WS/build/test_results/btr_fuzz/fuzz.xml" || fuzz_rc=$?
fi

summary="$(catkin_test_results build/test_results 2>&1)"
results_rc=$?
echo "$summary" | tail -n 30

# Count test cases from the JUnit XML files (gtest and rostest both write them).
read -r total failed < <(/usr/bin/python3 - build/test_results <<'PY'
import sys, glob, os
import xml.etree.ElementTree as ET
total = failed = 0
for path in glob.glob(os.path.join(sys.argv[1], '**', '*.xml'), recursive=True):
    try:
        root = ET.parse(path).getroot()
    except ET.ParseError:
        failed += 1; total += 1; continue
    suites = [root] if root.tag == 'testsuite' else root.iter('testsuite')
    for s in suites:
        for case in s.iter('testcase'):
            total += 1
            if case.find('failure') is not None or case.find('error') is not None:
                failed += 1
print(total, failed)
PY
)
passed=$((total - failed))
if [ "$build_rc" -ne 0 ] || [ "$results_rc" -ne 0 ] || [ "$fuzz_rc" -ne 0 ] || [ "$total" -eq 0 ]; then
  [ "$failed" -eq 0 ] && failed=1
  echo "$passed passed, $failed failed"
  exit 1
fi
echo "$passed passed, $failed failed"
