// One quick-suite run of btr_experiments, with each step's stop and, with PROBE_V=1, every
// Newton iteration (energy, gradient, alpha, inverted tetrahedra). It showed why the surface
// step on soft tissue stopped far from equilibrium before 64fa080 (BENCHMARKS.md, "Inverted
// elements at the limit"): alpha 1/64 ... 1e-9 at about 590 N, then a fold on the settled
// projections. Build against the package's libraries (after scripts/setup.sh):
//   L=build/ws/devel/lib; g++ -std=c++17 -O2 -Iinclude -I/usr/include/eigen3 bench/probes/suite_run_trace.cpp \
//     -o /tmp/trace -L$L -lbtr_simulation -lbtr_registration -lbtr_io -lbtr_geometry -lbtr_fem -lbtr_base -Wl,-rpath,$PWD/$L
//   PROBE_V=1 /tmp/trace phantom 400 practical surface surface      # MODEL|phantom E experiment setting value
// PROBE_STALL=N sets stall_projections, PROBE_ISA=a the surface step's inversion_stall_alpha.
// PROBE_REST=estimated gives the run that rest shape (default prone: the thesis's), and with
// it the stiffness search's candidates and the estimate are printed; PROBE_CT=t sets the
// candidates' unload tolerance (1e-5: as before a4689ef). The stiffness search at the soft end
// (BENCHMARKS.md) was measured with
//   PROBE_REST=estimated /tmp/trace phantom 300 practical full full
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>
#include "breast_tumour_registration/registration/registration_engine.h"
#include "breast_tumour_registration/simulation/experiment_suite.h"
#include "breast_tumour_registration/simulation/phantom.h"
#include "breast_tumour_registration/simulation/rest_model_io.h"
using namespace btr;
int main(int argc, char** argv) {
  // probe MODEL|phantom E experiment setting variable value [max_iter]
  std::string model_path = argv[1];
  double E = std::atof(argv[2]);
  PhantomModel model;
  if (model_path == "phantom") { PhantomOptions po; po.tet.cell_size = 0.008; model = make_phantom_model(po); }
  else model = load_rest_model(model_path);
  PhantomSceneOptions gen; gen.youngs_modulus = E;
  const PhantomConfigurations conf = simulate_phantom(model, gen);
  ExperimentSuiteOptions o; o.quick = true;
  for (const auto& run : plan_experiments(o)) {
    if (run.experiment != argv[3] || run.setting != argv[4] || run.value != argv[5]) continue;
    const char* rest = std::getenv("PROBE_REST");
    const auto t0 = std::chrono::steady_clock::now();
    RegistrationEngine engine(experiment_scene(model, conf, run, "balanced", rest ? rest : "prone"));
    RegistrationOptions ro = preset_options("balanced");
    ro.landmark.weight = run.landmark_weight;
    if (argc > 6) ro.surface.newton.max_iterations = std::atoi(argv[6]);
    if (std::getenv("PROBE_STALL")) ro.surface.stall_projections = std::atoi(std::getenv("PROBE_STALL"));
    if (std::getenv("PROBE_ISA")) ro.surface.inversion_stall_alpha = std::atof(std::getenv("PROBE_ISA"));
    if (std::getenv("PROBE_NPP")) ro.surface.newton_per_projection = std::atoi(std::getenv("PROBE_NPP"));
    if (std::getenv("PROBE_CAP")) ro.surface.max_projections = std::atoi(std::getenv("PROBE_CAP"));
    if (std::getenv("PROBE_HOLD")) ro.surface.hold_contraction = std::atof(std::getenv("PROBE_HOLD"));
    if (std::getenv("PROBE_CT")) ro.stiffness.candidate_tolerance = std::atof(std::getenv("PROBE_CT"));
    auto cb = [](const std::string& step, const IterationInfo& it) {
      if (std::getenv("PROBE_V")) std::printf("  %s it %d E %.6g |g| %.3g alpha %.3g inv %ld\n", step.c_str(), it.iteration, it.energy, it.gradient_norm, it.alpha, it.inverted);
      return true; };
    const RegistrationResult r = engine.solve(ro, cb);
    for (const auto& c : r.stiffness_evaluations)
      std::printf("  candidate E %.1f Pa: misfit %.4f mm, %d forward solves, %.2f s%s%s\n", c.youngs_modulus, c.misfit * 1e3,
                  c.forward_solves, c.seconds, c.failure.empty() ? "" : ": ", c.failure.c_str());
    for (const auto& rep : r.reports)
    {
      std::printf("%s: %s inv %ld %.2f s: %s\n", rep.name.c_str(), rep.converged ? "C" : "NC", rep.inverted, rep.seconds, rep.stop_reason.c_str());
      if (std::getenv("PROBE_RES")) {
        std::printf("  held from %d; residuals [mm]:", rep.sliding_held_from);
        for (double q : rep.projection_residuals) std::printf(" %.3f", q * 1e3);
        std::printf("\n");
      }
    }
    double w = 0; for (auto& t : r.tumours) w = std::max(w, t.centroid_distance);
    if (r.estimated_youngs_modulus > 0) std::printf("estimated E %.2f Pa\n", r.estimated_youngs_modulus);
    std::printf("worst %.4f mm, %.2f s\n", w * 1e3, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  }
}
