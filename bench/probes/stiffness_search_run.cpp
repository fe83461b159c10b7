// One registration of the quick suite's practical experiment with the stiffness estimated: the
// search's candidates (E, landmark misfit), each step's verdict and time, the worst tumour. It
// measured the stiffness search at the soft end (BENCHMARKS.md, "The stiffness search at the
// soft end"). Build against the package's libraries (after scripts/setup.sh):
//   L=build/ws/devel/lib; g++ -std=c++17 -O2 -Iinclude -I/usr/include/eigen3 bench/probes/stiffness_search_run.cpp \
//     -o /tmp/search -L$L -lbtr_simulation -lbtr_registration -lbtr_io -lbtr_geometry -lbtr_fem -lbtr_base -Wl,-rpath,$PWD/$L
//   /tmp/search phantom 300 full            # MODEL|phantom E setting (rigid landmarks surface gravity+surface full)
//   CT=1e-5 /tmp/search phantom 300 full    # the candidates unloaded to the unload's own tolerance (as before a4689ef)
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
  std::string model_path = argv[1];
  double E = std::atof(argv[2]);
  PhantomModel model;
  if (model_path == "phantom") { PhantomOptions po; po.tet.cell_size = 0.008; model = make_phantom_model(po); }
  else model = load_rest_model(model_path);
  PhantomSceneOptions gen; gen.youngs_modulus = E;
  const PhantomConfigurations conf = simulate_phantom(model, gen);
  ExperimentSuiteOptions o; o.quick = true;
  for (const auto& run : plan_experiments(o)) {
    if (run.experiment != "practical" || run.setting != argv[3]) continue;
    auto t0 = std::chrono::steady_clock::now();
    RegistrationEngine engine(experiment_scene(model, conf, run, "balanced", "estimated"));
    auto t1 = std::chrono::steady_clock::now();
    RegistrationOptions ro = preset_options("balanced");
    if (std::getenv("CT")) ro.stiffness.candidate_tolerance = std::atof(std::getenv("CT"));
    const RegistrationResult r = engine.solve(ro);
    auto t2 = std::chrono::steady_clock::now();
    for (auto& [e, m] : r.stiffness_evaluations) std::printf("  E %.1f misfit %.4f mm\n", e, m * 1e3);
    for (const auto& rep : r.reports) std::printf("%s: %s %.2fs: %s\n", rep.name.c_str(), rep.converged ? "C" : "NC", rep.seconds, rep.stop_reason.c_str());
    double w = 0; for (auto& t : r.tumours) w = std::max(w, t.centroid_distance);
    std::printf("E est %.2f worst %.4f mm prepare %.2fs solve %.2fs\n", r.estimated_youngs_modulus, w * 1e3,
      std::chrono::duration<double>(t1-t0).count(), std::chrono::duration<double>(t2-t1).count());
  }
}
