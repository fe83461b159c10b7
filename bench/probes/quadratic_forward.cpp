// Does a quadratic prone model close the gap the linear one leaves (issue 13)? Against another
// code's truth (SfePy, bench/make_independent_truth.py) with nothing estimated: the true rest
// shape, E and tissue layout, re-meshed at each cell size given. For linear tetrahedra (element
// and nodal volume forms) and quadratic ones (ForwardGravityOptions::element_order), each row:
//   prone   gravity from the true rest shape, against the prone tumours (the forward model the
//           unloaded shape inverts)
//   supine  gravity from the true rest shape, against the supine tumours
//   rest    the prone image unloaded at the true E with that model: the tumours' rest centroids
//           (carried by the estimate) against the true rest shape's
//   unload  then supine gravity from the estimate (no surface or landmark step), against the
//           supine tumours
// Worst tumour centroid distance [mm] and seconds. Build against the package's libraries:
//   L=build/ws/devel/lib
//   g++ -std=c++17 -O2 -fopenmp -Iinclude -I/usr/include/eigen3 bench/probes/quadratic_forward.cpp -o /tmp/qfwd -L$L -lbtr_simulation -lbtr_registration -lbtr_io -lbtr_geometry -lbtr_fem -lbtr_base -Wl,-rpath,$PWD/$L
//   cd TRUTH && OMP_NUM_THREADS=2 /tmp/qfwd model_regions.yaml truth.yaml 500 0 7 5   # 0: the model's own mesh
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>
#include "breast_tumour_registration/fem/forward_gravity.h"
#include "breast_tumour_registration/fem/unloaded_shape.h"
#include "breast_tumour_registration/geometry/metrics.h"
#include "breast_tumour_registration/registration/registration_pipeline.h"
#include "breast_tumour_registration/registration/simulation_mesh.h"
#include "breast_tumour_registration/registration/unload_step.h"
#include "breast_tumour_registration/simulation/experiment_suite.h"
#include "breast_tumour_registration/simulation/given_truth_io.h"
#include "breast_tumour_registration/simulation/rest_model_io.h"
using namespace btr;

struct Model {
  const char* name;
  VolumeForm form;
  ElementOrder order;
  int degree;
  QuadraticVolume volume;
};

// Tumour vertex positions under node positions x (corners; plus edge nodes when quadratic).
static Points tumour_positions(const RegistrationModel& rm, const EmbeddedTumour& t, const ForwardGravity& phi,
                               const Points& x) {
  if (phi.quadratic_nodes().rows() == 0) return apply_embedding(t.embedding, rm.rest.T, x);
  return apply_quadratic_embedding(t.embedding, phi.quadratic_mesh(), phi.quadratic_nodes());
}

static double worst_error(const RegistrationModel& rm, const ForwardGravity& phi, const Points& x,
                          const std::map<std::string, SurfaceMesh>& truth) {
  double worst = 0;
  for (const auto& t : rm.tumours) {
    const SurfaceMesh s{tumour_positions(rm, t, phi, x), t.prone.F};
    worst = std::max(worst, (volume_centroid(s) - volume_centroid(truth.at(t.name))).norm() * 1e3);
  }
  return worst;
}

int main(int argc, char** argv) {
  if (argc < 5) {
    std::fprintf(stderr, "usage: %s MODEL TRUTH E CELL_MM...\n", argv[0]);
    return 2;
  }
  const PhantomModel model = load_rest_model(argv[1]);
  const double E = std::atof(argv[3]);
  const PhantomConfigurations conf = load_given_configurations(argv[2], model).at(E);
  const QuadraticVolume Q = QuadraticVolume::Quadrature, M = QuadraticVolume::ElementMean;
  const std::vector<Model> all = {{"linear element", VolumeForm::Element, ElementOrder::Linear, 0, Q},
                                  {"linear nodal", VolumeForm::Nodal, ElementOrder::Linear, 0, Q},
                                  {"quadratic, 4 points", VolumeForm::Element, ElementOrder::Quadratic, 2, Q},
                                  {"quadratic, 14 points", VolumeForm::Element, ElementOrder::Quadratic, 5, Q},
                                  {"quadratic mean, 14 p.", VolumeForm::Element, ElementOrder::Quadratic, 5, M}};
  // PROBE_MODELS=0,1,4 runs those rows only (default: all).
  std::vector<Model> models;
  const std::string only = std::getenv("PROBE_MODELS") ? std::getenv("PROBE_MODELS") : "";
  for (size_t i = 0; i < all.size(); ++i)
    if (only.empty() || ("," + only + ",").find("," + std::to_string(i) + ",") != std::string::npos) models.push_back(all[i]);
  for (int a = 4; a < argc; ++a) {
    const double h = std::atof(argv[a]) * 1e-3;
    ExperimentRun run;
    run.experiment = "forward";
    run.method_youngs_modulus = E;
    run.steps = {"gravity"};
    std::vector<std::string> warnings;
    run.rest_shape = "rest";
    auto meshed = [&](const Scene& s) { return h > 0 ? with_simulation_mesh(s, h, 0) : s; };  // 0: the model's own mesh
    const RegistrationModel rm = prepare_model(meshed(experiment_scene(model, conf, run, "balanced", "rest")), warnings);
    run.rest_shape = "prone";
    const RegistrationModel pm = prepare_model(meshed(experiment_scene(model, conf, run, "balanced", "prone")), warnings);
    std::printf("cell %s mm: %ld tets (rest), %ld (prone image)\n", argv[a], long(rm.rest.T.rows()), long(pm.rest.T.rows()));
    for (const Model& m : models) {
      ForwardGravityOptions fo;
      fo.element_order = m.order;
      fo.quadrature_degree = std::max(2, m.degree);
      fo.quadratic_volume = m.volume;
      fo.newton.gradient_rel_tolerance = 1e-8;
      auto phi = [&](const RegistrationModel& r) {
        return ForwardGravity(r.rest.T, r.rest.V.rows(), r.chest_wall, r.materials, r.material_of, m.form, 0,
                              r.material.density, fo);
      };
      ForwardGravity f = phi(rm);
      auto t0 = std::chrono::steady_clock::now();
      Points xp = rm.rest.V;
      f.solve(rm.rest.V, model.prone_gravity, xp);
      const double prone = worst_error(rm, f, xp, conf.tumour_prone);
      const double tp = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      Points xs = rm.rest.V;
      f.solve(rm.rest.V, rm.gravity, xs);
      const double supine = worst_error(rm, f, xs, conf.tumour_supine);

      // Unload the prone image with this model, then supine gravity from the estimate.
      t0 = std::chrono::steady_clock::now();
      try {
      const TetMesh loaded{pm.prone, pm.rest.T};
      UnloadProblem pb = unload_problem(pm, loaded, model.prone_gravity);
      pb.volume_form = m.form;
      UnloadOptions uo;
      uo.forward = fo;
      const UnloadResult u = estimate_unloaded_shape(pb, uo);
      const double tu = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      // The tumours are embedded in the prone image's straight tetrahedra: the material point at
      // barycentric b of the rest element sits at the quadratic prone map of b, which is the
      // embedded point only where the prone edges do not bulge; see the row's note.
      ForwardGravity g = phi(pm);
      Points xu = u.rest;
      g.solve(u.rest, pm.gravity, xu);
      const double unload = worst_error(pm, g, xu, conf.tumour_supine);
      double rest = 0;  // the tumours' material points in the estimate, against their true rest positions
      for (size_t i = 0; i < pm.tumours.size(); ++i) {
        const SurfaceMesh s{apply_embedding(pm.tumours[i].embedding, pm.rest.T, u.rest), pm.tumours[i].prone.F};
        rest = std::max(rest, (volume_centroid(s) - volume_centroid(rm.tumours.at(i).prone)).norm() * 1e3);
      }
      std::printf("  %-22s prone %.2f  supine %.2f  rest %.2f  unload+supine %.2f mm  (prone solve %.1f s, unload %s in %.1f s, "
                  "%d forward solves, mismatch %.4f mm)\n",
                  m.name, prone, supine, rest, unload, tp, u.converged ? "converged" : "NOT converged", tu, u.iterations,
                  u.max_mismatch * 1e3);
      } catch (const std::exception& ex) {
        std::printf("  %-22s prone %.2f  supine %.2f  (prone solve %.1f s; unload: %s)\n", m.name, prone, supine, tp, ex.what());
      }
      std::fflush(stdout);
    }
  }
}
