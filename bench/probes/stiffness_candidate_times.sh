#!/usr/bin/env bash
# The stiffness search's candidates, each timed (BENCHMARKS.md, "The stiffness search and the
# heap"): builds a copy of src/registration/stiffness_step.cpp whose candidate evaluation prints
# its modulus, misfit and time to stderr, and links it before the package's library (the
# executable's definition wins), with bench/probes/register_once.cpp or src/tools/btr_experiments.cpp.
# Usage (after scripts/setup.sh): bash bench/probes/stiffness_candidate_times.sh OUT [experiments]
#   OUT SCENE.yaml            one registration        OUT --model M --truth T ...   the suite
set -euo pipefail
cd "$(dirname "$0")/../.."
OUT=${1:?usage: stiffness_candidate_times.sh OUT [experiments]}
SRC=$(mktemp --suffix=.cpp)
/usr/bin/python3 - "$SRC" <<'PY'
import sys
s = open('src/registration/stiffness_step.cpp').read()
s = s.replace('  auto evaluate = [&](double E) {\n    Candidate c;', '  auto evaluate_inner = [&](double E) {\n    Candidate c;', 1)
s = s.replace('  // The grid walk (stiffness_grid_walk.h)', '''  auto evaluate = [&](double E) {
    const auto ta = std::chrono::steady_clock::now();
    Candidate c = evaluate_inner(E);
    std::fprintf(stderr, "candidate %8.1f Pa misfit %.4f mm unload %.3f s total %.3f s\\n", E, c.misfit * 1e3, c.unload.seconds,
                 std::chrono::duration<double>(std::chrono::steady_clock::now() - ta).count());
    return c;
  };
  // The grid walk (stiffness_grid_walk.h)''', 1)
assert 'evaluate_inner' in s and 'candidate %8.1f' in s
open(sys.argv[1], 'w').write(s)
PY
MAIN=bench/probes/register_once.cpp
[ "${2:-}" = experiments ] && MAIN=src/tools/btr_experiments.cpp
L=build/ws/devel/lib
g++ -std=c++17 -O2 -fopenmp -Iinclude -I/usr/include/eigen3 -I/usr/include/suitesparse "$MAIN" "$SRC" -o "$OUT" \
  -L$L -lbtr_simulation -lbtr_registration -lbtr_io -lbtr_geometry -lbtr_fem -lbtr_base -Wl,-rpath,$PWD/$L
rm -f "$SRC"
