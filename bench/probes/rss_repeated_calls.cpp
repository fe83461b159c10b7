// Resident memory over repeated registrations on one engine (the node's pattern): BENCHMARKS.md,
// "The stiffness search and the heap". Build against the package's libraries (after scripts/setup.sh):
//   L=build/ws/devel/lib; g++ -std=c++17 -O2 -Iinclude -I/usr/include/eigen3 bench/probes/rss_repeated_calls.cpp \
//     -o /tmp/rss_repeat -L$L -lbtr_simulation -lbtr_registration -lbtr_io -lbtr_geometry -lbtr_fem -lbtr_base -Wl,-rpath,$PWD/$L
//   OMP_NUM_THREADS=1 /tmp/rss_repeat test/data/independent_truth_E1000/scene_estimated_regions_nodal.yaml 30
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <unistd.h>
#include "breast_tumour_registration/registration/registration_engine.h"
#include "breast_tumour_registration/io/scene.h"
using namespace btr;
static double rss_mb() { std::ifstream f("/proc/self/statm"); long a, b; f >> a >> b; return b * sysconf(_SC_PAGESIZE) / 1048576.0; }
int main(int argc, char** argv) {
  RegistrationEngine engine(load_scene(argv[1]));
  const int n = std::atoi(argv[2]);
  RegistrationOptions ro = preset_options("balanced");
  for (int i = 1; i <= n; ++i) {
    const auto r = engine.solve(ro);
    if (i == 1 || i % 5 == 0) std::printf("call %d: rss %.1f MB (%.2f s)\n", i, rss_mb(), r.seconds);
  }
}
