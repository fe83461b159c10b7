// How far our FEM's forward answer lies from another code's truth, with nothing estimated:
// the true rest shape, the true fat E and tissue layout, supine gravity only (the step
// `gravity`), on the model's own mesh and re-meshed at each cell size given. What is left is
// discretization (linear against SfePy's quadratic or cubic tetrahedra) and the material law, the floor
// under any registration of that truth. Build against the package's libraries (after
// scripts/setup.sh):
//   L=build/ws/devel/lib
//   g++ -std=c++17 -O2 -Iinclude -I/usr/include/eigen3 bench/probes/forward_discrepancy.cpp -o /tmp/fwd -L$L -lbtr_simulation -lbtr_registration -lbtr_io -lbtr_geometry -lbtr_fem -lbtr_base -Wl,-rpath,$PWD/$L
//   cd TRUTH && /tmp/fwd model_regions.yaml truth.yaml 300 element|nodal 0 7 5 4   # 0: the model's own mesh
// PROBE_STEPS=full runs the whole default plan on the supine data instead of gravity alone, and
// PROBE_REST=unloaded|estimated starts from the unloaded shape at the true E or at an E estimated
// from the landmarks (the suite's settings), so that each estimate's share of the error shows.
// PROBE_POSE=prone simulates the prone pose from the true rest shape instead (the forward model
// the unloaded shape inverts), measured on the prone tumours. PROBE_SAG=1 also prints how far each
// tumour moved from its rest position here and in the truth. PROBE_UNLOAD_ORDER=quadratic unloads
// (and searches the stiffness) with quadratic elements (material.unload_element_order).
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>
#include "breast_tumour_registration/registration/registration_engine.h"
#include "breast_tumour_registration/registration/simulation_mesh.h"
#include "breast_tumour_registration/simulation/experiment_suite.h"
#include "breast_tumour_registration/simulation/given_truth_io.h"
#include "breast_tumour_registration/simulation/rest_model_io.h"
using namespace btr;
int main(int argc, char** argv) {
  if (argc < 6) {
    std::fprintf(stderr, "usage: %s MODEL TRUTH E element|nodal CELL_MM...\n", argv[0]);
    return 2;
  }
  const PhantomModel model = load_rest_model(argv[1]);
  const double E = std::atof(argv[3]);
  const PhantomConfigurations conf = load_given_configurations(argv[2], model).at(E);
  ExperimentRun run;
  run.experiment = "forward";
  const char* rest = std::getenv("PROBE_REST");
  const char* steps = std::getenv("PROBE_STEPS");
  const char* pose = std::getenv("PROBE_POSE");
  run.rest_shape = rest ? rest : "rest";
  run.method_youngs_modulus = E;
  if (!(steps && std::string(steps) == "full")) run.steps = {"gravity"};
  for (int a = 5; a < argc; ++a) {
    const double h = std::atof(argv[a]);
    Scene scene = experiment_scene(model, conf, run, "balanced", run.rest_shape);
    scene.material.volume_form = std::string(argv[4]) == "nodal" ? VolumeForm::Nodal : VolumeForm::Element;
    scene.nodal_fallback = false;
    if (const char* order = std::getenv("PROBE_UNLOAD_ORDER")) scene.material.unload_element_order = parse_element_order(order);
    if (pose && std::string(pose) == "prone") {
      scene.gravity = model.prone_gravity;
      for (auto& t : scene.tumours) t.supine_ground_truth = conf.tumour_prone.at(t.name);
    }
    if (h > 0) scene = with_simulation_mesh(scene, h * 1e-3, 0);
    const auto t0 = std::chrono::steady_clock::now();
    std::vector<std::string> warnings;
    RegistrationModel rm = prepare_model(scene, warnings);  // as the suite: this mesh, whatever the preset's
    if (rm.unload) {  // prepare_model unloads where the plan does (not when E is estimated)
      const StepReport& u = *rm.unload;
      std::printf("unload: %s (%s), rest shape moved up to %.2f mm, re-simulated prone within %.4f mm\n",
                  u.converged ? "converged" : "NOT converged", u.stop_reason.c_str(), u.unload.rest_change * 1e3,
                  u.unload.mismatch * 1e3);
    }
    const long tets = rm.rest.T.rows();
    RegistrationEngine engine(scene, std::move(rm), std::move(warnings));
    const RegistrationResult r = engine.solve(preset_options("balanced"));
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    double worst = 0;
    std::printf("cell %s mm, %ld tets, %s, %.1f s:", h > 0 ? argv[a] : "own", tets,
                r.converged ? "converged" : "NOT converged", s);
    for (const auto& t : r.tumours) {
      std::printf(" %s %.2f", t.name.c_str(), t.centroid_distance * 1e3);
      worst = std::max(worst, t.centroid_distance * 1e3);
    }
    if (r.estimated_youngs_modulus > 0) std::printf("  (E estimated %.0f Pa)", r.estimated_youngs_modulus);
    std::printf("  worst %.2f mm\n", worst);
    if (std::getenv("PROBE_SAG"))  // how far each tumour moved here and in the truth (rest as given: vertex mean)
      for (size_t i = 0; i < r.tumours.size(); ++i) {
        const Vec3 c0 = scene.tumours[i].prone.V.colwise().mean().transpose();
        std::printf("  %s moved %.2f mm here, %.2f mm in the truth\n", r.tumours[i].name.c_str(),
                    (r.tumours[i].centroid - c0).norm() * 1e3, r.tumours[i].rigid_centroid_distance * 1e3);
      }
    for (const auto& rep : r.reports)
      if (!rep.converged) std::printf("  %s: %s (%ld inverted)\n", rep.name.c_str(), rep.stop_reason.c_str(), long(rep.inverted));
    std::fflush(stdout);
  }
}
