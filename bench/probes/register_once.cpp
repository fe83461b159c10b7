// One registration of a scene through the engine, printing each stiffness candidate (its
// forward solves, seconds, and why it was not simulated), the estimated E and the worst tumour.
// BUDGET=f sets the candidates' forward-solve budget factor (0: none, as before 2026-12-06).
// Build as bench/probes/suite_run_trace.cpp, then:
//   BUDGET=0 /tmp/once SCENE.yaml [preset]
#include <cstdio>
#include <cstdlib>
#include "breast_tumour_registration/registration/registration_engine.h"
#include "breast_tumour_registration/io/scene.h"
using namespace btr;
int main(int argc, char** argv) {
  if (argc < 2) return 2;
  Scene s = load_scene(argv[1]);
  RegistrationEngine engine(s);
  RegistrationOptions ro = preset_options(argc > 2 ? argv[2] : "balanced");
  if (std::getenv("BUDGET")) ro.stiffness.candidate_budget_factor = std::atof(std::getenv("BUDGET"));
  const auto r = engine.solve(ro);
  for (const auto& c : r.stiffness_evaluations)
    std::printf("  candidate %8.1f Pa: misfit %.4f mm, %3d forward solves, %6.2f s%s%s\n", c.youngs_modulus, c.misfit * 1e3,
                c.forward_solves, c.seconds, c.failure.empty() ? "" : ": ", c.failure.c_str());
  for (const auto& w : r.warnings) std::printf("  warning: %s\n", w.c_str());
  double w = 0; for (auto& t : r.tumours) w = std::max(w, t.centroid_distance);
  std::printf("E %.1f worst %.4f mm, %.2f s, %s, %s form\n", r.estimated_youngs_modulus, w * 1e3, r.seconds,
              r.converged ? "converged" : "NC", to_string(r.volume_form));
}
