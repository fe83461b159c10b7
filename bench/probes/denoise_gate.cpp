// Registers a scene twice, the supine mesh's denoising (surface_denoising.h) off and forced on
// (threshold 1e-6 m), with the scene's preset, on the scene as load_meshed_scene meshes it;
// prints the estimated noise, the worst and mean tumour errors, convergence and projections.
// The threshold study of BENCHMARKS.md ("A noisy supine mesh is denoised").
//   L=build/ws/devel/lib; g++ -std=c++17 -O2 -Iinclude -I/usr/include/eigen3 bench/probes/denoise_gate.cpp
//     -o /tmp/denoise_gate -L$L -lbtr_simulation -lbtr_registration -lbtr_io -lbtr_geometry -lbtr_fem -lbtr_base -Wl,-rpath,$PWD/$L
//   /tmp/denoise_gate SCENE.yaml
#include <algorithm>
#include <cstdio>
#include <string>
#include "breast_tumour_registration/io/scene.h"
#include "breast_tumour_registration/registration/registration_pipeline.h"
#include "breast_tumour_registration/registration/simulation_mesh.h"
using namespace btr;
int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: %s SCENE.yaml\n", argv[0]);
    return 2;
  }
  const Scene s = load_meshed_scene(argv[1]);
  std::vector<std::string> w;
  const RegistrationModel m = prepare_model(s, w);
  for (double th : {0.0, 1e-6}) {
    RegistrationOptions o = preset_options(s.preset);
    o.surface.scan_denoising_min_noise = th;
    const RegistrationResult r = run_registration(s, m, o);
    double worst = 0, mean = 0;
    for (auto& t : r.tumours) { worst = std::max(worst, t.centroid_distance); mean += t.centroid_distance / r.tumours.size(); }
    std::printf("%s %s noise %.3f mm: worst %.3f mean %.3f mm, converged %d, projections %d\n", argv[1], th > 0 ? "denoised" : "as is   ",
                r.supine_noise * 1e3, worst * 1e3, mean * 1e3, (int)r.converged, r.reports.back().outer_iterations);
  }
}
