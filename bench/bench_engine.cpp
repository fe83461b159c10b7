// btr_bench_engine: what preparing once buys per call. For one scene and preset it times, in
// one run and interleaved (so that the shared machine's noise hits all three alike):
//   fresh    load the scene, prepare it (simulation mesh, model) and register: a call from nothing
//            (btr_register without its output files);
//   model    register on a model prepared before, every step building its solvers (the node
//            before the engine);
//   engine   RegistrationEngine::solve again on one engine: the model and every step's solver
//            (Hessian pattern, CHOLMOD symbolic analysis, subspace) kept.
// It prints the medians, the ratios and the largest vertex difference between the answers
// (the engine must not change them).
//   btr_bench_engine SCENE.yaml --preset balanced --repeats 9
#include <CLI/CLI.hpp>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <vector>

#include "breast_tumour_registration/base/errors.h"
#include "breast_tumour_registration/registration/registration_engine.h"

using namespace btr;

namespace {
double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}
double since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}
}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Time a registration from nothing, on a prepared model, and on a prepared engine."};
  std::string scene_path, preset = "balanced";
  int repeats = 9;
  app.add_option("scene", scene_path, "scene file (YAML)")->required();
  app.add_option("-p,--preset", preset, "fast, balanced or accurate")->capture_default_str();
  app.add_option("--repeats", repeats, "timed calls of each kind (median)")->check(CLI::Range(1, 1000))->capture_default_str();
  CLI11_PARSE(app, argc, argv);
  try {
    const RegistrationOptions opt = preset_options(preset);
    RegistrationEngine engine(load_scene(scene_path));
    const PreparedScene& prepared = engine.prepare(opt);
    RegistrationResult reference = engine.solve(opt);  // builds the solvers
    std::vector<double> fresh, model, kept;
    double worst_difference = 0;
    for (int i = 0; i < repeats; ++i) {
      auto t0 = std::chrono::steady_clock::now();
      RegistrationEngine once(load_scene(scene_path));
      const RegistrationResult a = once.solve(opt);
      fresh.push_back(since(t0));
      t0 = std::chrono::steady_clock::now();
      const RegistrationResult b = run_registration(prepared.scene, prepared.model, opt);
      model.push_back(since(t0));
      t0 = std::chrono::steady_clock::now();
      const RegistrationResult c = engine.solve(opt);
      kept.push_back(since(t0));
      for (const RegistrationResult* r : {&a, &b})
        worst_difference = std::max(worst_difference, (r->x - c.x).cwiseAbs().maxCoeff());
    }
    const double f = median(fresh), m = median(model), k = median(kept);
    std::printf("scene %s, preset %s: %ld vertices, %ld tetrahedra; %d calls of each kind\n", scene_path.c_str(), preset.c_str(),
                static_cast<long>(prepared.model.rest.V.rows()), static_cast<long>(prepared.model.rest.T.rows()), repeats);
    std::printf("fresh  (load + prepare + register)        median %.3f s\n", f);
    std::printf("model  (prepared model, solvers per call) median %.3f s\n", m);
    std::printf("engine (prepared engine, solvers kept)    median %.3f s\n", k);
    std::printf("ratios: fresh / engine %.2f, model / engine %.2f; solvers built %d, reused %d\n", f / k, m / k,
                engine.solvers_built(), engine.solvers_reused());
    std::printf("largest vertex difference between the answers: %.3g m (converged: %s)\n", worst_difference,
                reference.converged ? "yes" : "no");
    return worst_difference > 1e-9 ? 1 : 0;
  } catch (const InputError& e) {
    std::fprintf(stderr, "btr_bench_engine: invalid input: %s\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "btr_bench_engine: %s\n", e.what());
    return 1;
  }
}
