// Each stiffness-search candidate's unload on its own, timed (from inverse gravity, not warm
// started as the search does), on a rest model with a truth file, re-meshed at 7 mm as the
// suite's --simulation-cell-size 7 does. VERB=1 prints every Newton iteration of every forward
// solve (gradient, step length, inverted tetrahedra, whether the inversion rule cut the step);
// ISA and AB override the forward solves' inversion_stall_alpha and abandon_inverted_fraction
// (AB=0 ISA=0: as before ecc7e1c). It found the folding solves of SfePy's 300 Pa body
// with the nodal volume term (BENCHMARKS.md, "The stiffness search at the soft end"). Build as
// bench/probes/suite_run_trace.cpp, then:
//   VERB=1 /tmp/cand OUT/truth/model.yaml OUT/truth/truth.yaml 300 nodal 640   # model truth E form candidate-E...
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include "breast_tumour_registration/fem/forward_gravity.h"
#include "breast_tumour_registration/registration/registration_pipeline.h"
#include "breast_tumour_registration/registration/simulation_mesh.h"
#include "breast_tumour_registration/registration/stiffness_step.h"
#include "breast_tumour_registration/registration/unload_step.h"
#include "breast_tumour_registration/simulation/experiment_suite.h"
#include "breast_tumour_registration/simulation/given_truth_io.h"
#include "breast_tumour_registration/simulation/rest_model_io.h"
using namespace btr;
using Clock = std::chrono::steady_clock;
int main(int argc, char** argv) {
  // cand_probe model.yaml truth.yaml E form(element|nodal) candidateE...
  PhantomModel model = load_rest_model(argv[1]);
  auto confs = load_given_configurations(argv[2], model);
  const PhantomConfigurations& conf = confs.at(std::atof(argv[3]));
  ExperimentSuiteOptions o; o.quick = true;
  ExperimentRun run;
  for (const auto& r : plan_experiments(o)) if (r.experiment == "practical" && r.setting == "full") run = r;
  Scene scene = experiment_scene(model, conf, run, "balanced", "estimated");
  scene.material.volume_form = std::string(argv[4]) == "nodal" ? VolumeForm::Nodal : VolumeForm::Element;
  scene = with_simulation_mesh(scene, 0.007, 0);
  std::vector<std::string> w;
  RegistrationModel rm = prepare_model(scene, w);
  const double E0 = rm.material.youngs_modulus;
  const TetMesh prone{rm.prone, rm.rest.T};
  UnloadOptions uo = RegistrationOptions().stiffness.unload;
  uo.tolerance = 1e-4;
  if (std::getenv("ISA")) uo.forward.newton.inversion_stall_alpha = std::atof(std::getenv("ISA"));
  if (std::getenv("AB")) uo.forward.newton.abandon_inverted_fraction = std::atof(std::getenv("AB"));
  if (std::getenv("VERB")) uo.forward.newton.callback = [](const IterationInfo& it) {
    std::printf("   it %d |g| %.3g alpha %.3g step %.3g mm inv %ld fact %d pcg %d lim %d\n", it.iteration, it.gradient_norm, it.alpha, it.step_norm * 1e3, it.inverted, it.factorized, it.pcg_iterations, it.inversion_limited);
    return true; };
  for (int i = 5; i < argc; ++i) {
    const double E = std::atof(argv[i]), k = E / E0;
    UnloadProblem pb = unload_problem(rm, prone, *scene.prone_gravity / k);
    const auto t0 = Clock::now();
    UnloadResult u = estimate_unloaded_shape(pb, uo);
    const auto t1 = Clock::now();
    std::printf("E %.0f: unload %s %d solves, %d stages, %d newton, %d load steps, mismatch %.3g mm, %.1f s: %s\n", E,
                u.converged ? "C" : "NC", u.iterations, u.continuation_stages, u.newton_iterations, u.load_steps,
                u.max_mismatch * 1e3, std::chrono::duration<double>(t1 - t0).count(), u.stop_reason.c_str());
    std::fflush(stdout);
  }
}
