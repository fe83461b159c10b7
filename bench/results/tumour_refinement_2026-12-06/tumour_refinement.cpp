// Does a mesh finer around the tumours pay? The default call (balanced: the nodal form at 9 mm
// where a scene unloads) on a prone surface meshed at 9 mm, with and without finer cells in
// each tumour's bounding ball (graded to 9 mm around it), at a few cell sizes within 1 % of
// 9 mm (a mesh is one draw: BENCHMARKS.md, "One mesh is one draw").
// Build against the package's libraries (after scripts/setup.sh):
//   L=build/ws/devel/lib; g++ -std=c++17 -O2 -Iinclude -I/usr/include/eigen3 bench/probes/tumour_refinement.cpp \
//     -o /tmp/tumour_refinement -L$L -lbtr_simulation -lbtr_registration -lbtr_io -lbtr_geometry -lbtr_fem -lbtr_base \
//     -Wl,-rpath,$PWD/$L
//   /tmp/tumour_refinement SCENE.yaml TUMOUR_CELL_MM [GRADING]
#include <algorithm>
#include <cstdio>
#include <cstdlib>

#include "breast_tumour_registration/io/scene.h"
#include "breast_tumour_registration/registration/registration_engine.h"
#include "breast_tumour_registration/registration/simulation_mesh.h"
using namespace btr;

int main(int argc, char** argv) {
  if (argc < 3) return 2;
  const double tumour_cell = std::atof(argv[2]) / 1000.0;
  for (double c_mm : {8.91, 8.955, 9.0, 9.045, 9.09})
    for (double tc : {0.0, tumour_cell}) {
      Scene s = load_scene(argv[1]);
      mesh_prone(s, c_mm / 1000.0, tc);
      RegistrationOptions opt = preset_options("balanced");
      opt.simulation_cell_size = opt.nodal_simulation_cell_size = 0;  // the mesh made here
      RegistrationEngine engine(s);
      const RegistrationResult r = engine.solve(opt);
      double worst = 0, axis = 0;
      for (const auto& t : r.tumours) {
        worst = std::max(worst, t.centroid_distance);
        if (t.truth_axis_ratio > 0) axis = std::max(axis, std::abs(t.axis_ratio / t.truth_axis_ratio - 1));
      }
      std::printf("cell %.3f mm tumour cell %.1f mm: %5ld vertices %6ld tets, worst %.3f mm, axis ratio off by %.1f %%, "
                  "%.2f s, %s, %s form\n", c_mm, tc * 1e3, static_cast<long>(s.prone.V.rows()), static_cast<long>(s.prone.T.rows()),
                  worst * 1e3, axis * 100, r.seconds, r.converged ? "converged" : "NOT converged", to_string(r.volume_form));
      std::fflush(stdout);
    }
}
