// Probe (issue 14): the tumours' response to Poisson's ratio, whole re-registrations against
// the linear region's tangent in the volume compliance q = (1 - 2 nu) / (2 nu). The scene is
// registered at nu 0.49 with the linear region, then at each other nu; per tumour it prints the
// shift projected on the tangent's prediction over the prediction's length (1: the tangent is
// right), and the surface step's sliding state, which sets the map the tangent is taken on
// (held where the skin settled, or free: registration_pipeline.cpp).
//   nu_response SCENE.yaml [tight] [nu ...]
// tight: the surface step run far past the balanced preset's tolerances (as btr_bench_uncertainty).
// Build as bench/probes/suite_run_trace.cpp (same libraries).
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "breast_tumour_registration/registration/registration_engine.h"
#include "breast_tumour_registration/registration/tumour_uncertainty.h"

using namespace btr;

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: nu_response SCENE.yaml [tight] [nu ...]\n");
    return 2;
  }
  const Scene base = load_scene(argv[1]);
  bool tight = false;
  std::vector<double> nus;
  for (int i = 2; i < argc; ++i) {
    if (std::string(argv[i]) == "tight") tight = true;
    else nus.push_back(std::atof(argv[i]));
  }
  if (nus.empty()) nus = {0.485, 0.47, 0.45};
  RegistrationOptions o = preset_options("balanced");
  o.uncertainty.enabled = true;
  if (tight) {
    o.landmark.newton.gradient_rel_tolerance = 1e-9;
    o.surface.newton.gradient_rel_tolerance = 1e-9;
    o.surface.projection_tolerance = 1e-7;
    o.surface.max_projections = 3000;
    o.surface.stall_projections = 100;
  }
  auto run = [&](double nu) {
    Scene s = base;
    s.material.poisson_ratio = nu;
    return RegistrationEngine(s).solve(o);
  };
  const RegistrationResult r0 = run(0.49);
  const StepReport& sr = r0.reports.back();
  std::printf("nu 0.49 (%s): %s, E %.0f Pa, %d projections, sliding held from projection %d (0: free)\n", tight ? "tight" : "balanced",
              r0.converged ? "converged" : "not converged", r0.estimated_youngs_modulus, sr.outer_iterations, sr.sliding_held_from);
  for (double nu : nus) {
    const RegistrationResult r = run(nu);
    const double dq = volume_compliance(nu) - volume_compliance(0.49);
    for (size_t i = 0; i < r.tumours.size(); ++i) {
      const Vec3 p = r0.tumours[i].uncertainty->d_volume_compliance * dq;
      const Vec3 d = r.tumours[i].centroid - r0.tumours[i].centroid;
      std::printf("nu %.3f dq %.4f %-7s shift / linear %.2f (linear %.3f mm), E %.0f Pa\n", nu, dq, r.tumours[i].name.c_str(),
                  d.dot(p) / p.dot(p), 1e3 * p.norm(), r.estimated_youngs_modulus);
    }
  }
}
