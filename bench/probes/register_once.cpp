// One registration of a scene through the engine, printing the estimated E and the worst tumour:
// the driver of bench/probes/stiffness_candidate_times.sh, which links it against a copy of the
// stiffness search that times each candidate.
#include <cstdio>
#include "breast_tumour_registration/registration/registration_engine.h"
#include "breast_tumour_registration/io/scene.h"
using namespace btr;
int main(int argc, char** argv) {
  Scene s = load_scene(argv[1]);
  RegistrationEngine engine(s);
  RegistrationOptions ro = preset_options(argc > 2 ? argv[2] : "balanced");
  const auto r = engine.solve(ro);
  double w = 0; for (auto& t : r.tumours) w = std::max(w, t.centroid_distance);
  std::printf("E %.1f worst %.4f mm, %.2f s, %s\n", r.estimated_youngs_modulus, w * 1e3, r.seconds, r.converged ? "converged" : "NC");
}
