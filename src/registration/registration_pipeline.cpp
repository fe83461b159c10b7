#include "breast_tumour_registration/registration/registration_pipeline.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>

#include "breast_tumour_registration/base/errors.h"
#include "breast_tumour_registration/base/units.h"
#include "breast_tumour_registration/fem/tet_kinematics.h"
#include "breast_tumour_registration/geometry/metrics.h"
#include "breast_tumour_registration/geometry/surface_attachment.h"
#include "breast_tumour_registration/geometry/validation.h"
#include "breast_tumour_registration/registration/fold_advice.h"
#include "breast_tumour_registration/registration/material_regions.h"
#include "breast_tumour_registration/registration/registration_step.h"
#include "breast_tumour_registration/registration/simulation_mesh.h"

namespace btr {
namespace {
using Clock = std::chrono::steady_clock;
double since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

bool requested(const Scene& s, const char* step) {
  return std::find(s.steps.begin(), s.steps.end(), step) != s.steps.end();
}
/// Flags a result that its own data contradict (RegistrationOptions' plausibility bounds).
void check_plausibility(const RegistrationModel& model, const RegistrationOptions& opt, RegistrationResult& r) {
  const Vec3 extent = (model.prone.colwise().maxCoeff() - model.prone.colwise().minCoeff()).transpose();
  const double diagonal = extent.norm();
  const double lm_bound = std::max(opt.landmark_residual_bound, opt.landmark_residual_fraction * diagonal);
  // Only where the landmarks were constraints: without the landmark step their residual
  // measures how far the skin slid along the surface, which the surface step leaves free.
  if (r.steps.landmarks && r.landmark_residual_max > lm_bound) {
    r.implausible = true;
    r.warnings.push_back("implausible result: a landmark ends " + format_mm(r.landmark_residual_max) +
                         " from its supine position (bound " + format_mm(lm_bound) +
                         "): the model cannot follow its data (far too stiff, locking near nu = 0.5, a wrong "
                         "pose, or a mislabelled landmark pair)");
  }
  const double skin_bound = std::max(opt.skin_distance_bound, opt.skin_distance_fraction * diagonal);
  if (r.skin_distance_mean > skin_bound) {
    r.implausible = true;
    r.warnings.push_back("implausible result: the skin ends " + format_mm(r.skin_distance_mean) +
                         " from the supine surface on average (bound " + format_mm(skin_bound) +
                         "): a wrong pose, a scan of another region, or a model that cannot follow it");
  }
  if (r.rigid_pose_undecided) r.implausible = true;
}

}  // namespace

namespace {

// A preset is a set of tolerances (what "converged" means for it) and a simulation mesh; the
// iteration caps are generous safety limits, reported as not converged when hit. Each is a point
// on the measured speed/accuracy front of two bodies, the 35k-tet phantom and SfePy's
// independent truth (BENCHMARKS.md, "The preset table re-chosen"). Accurate's tolerances
// converge on both since a creeping skin's sliding is held, and at 4 mm they are the most
// accurate point of both fronts (the scene's own mesh was dominated on both). Where a scene
// unloads and leaves the form to auto, balanced takes the nodal form at 9 mm (2026-12-06,
// seventh session: nearer on six of seven bodies at a median 1.03 times the time) and accurate
// the nodal form at 5 mm (eighth session, over three meshes per point on SfePy's five settings:
// nearer than the default balanced on four, the element form at 4 mm on two; BENCHMARKS.md,
// "The balanced preset's fallback, and one mesh is one draw"). With that nodal form balanced
// unloads with quadratic elements (2026-12-07: nearer on 11 of 15 scenes, 7 chosen on and 8 made
// after, within 0.003 mm on the rest, at a median 2.2 times the call; at accurate's 5 mm it
// gained nothing consistent; BENCHMARKS.md, "The quadratic unload in the balanced preset").
// Accurate then ended farther than balanced on 9 of those 15 scenes at 5.9 times its time; with
// balanced's model at 7 mm (nodal, quadratic unload) and its own tolerances it is nearer than the
// 5 mm point on 11 of 15 at 0.46 times its time, and nearer than balanced on 9 at 2.7 times
// (2026-12-07, fourth session; BENCHMARKS.md, "The accurate preset on balanced's model, and the
// unload's 4-point rule").
// Fast, with the element form at 9 mm, ended 2.7 times as far as balanced (median) on those 15
// scenes at 0.22 times its time, farther on all 15. Where a scene unloads and leaves the form
// to auto it takes the nodal form at 11 mm with the linear unload (2026-12-07, fifth session):
// nearer than before on all 7 scenes the size was chosen on and on 7 of the 8 held out, at a
// median 1.11 times its time over the 15 (BENCHMARKS.md, "The fast preset on the nodal form").
// Accurate meshes each tumour's bounding ball at 4 mm (2026-12-07, seventh session, five mesh
// draws per scene, a rule fixed before the run: the stiff tumours' axis ratio nearer on all six
// resolved truths, the worst tumour on five, a median 0.94 times as far on nine held out, at 1.10
// to 1.54 times the call; BENCHMARKS.md, "Finer cells around the tumours in the accurate
// preset"); at balanced's and fast's sizes it cost 1.25 to 2.3 times their call.
struct Preset {
  const char* name;
  double simulation_cell_size;    ///< [m]; 0: the scene's own mesh
  int subspace_handles;
  double gradient_rel_tolerance;  ///< landmark and surface Newton
  double projection_tolerance;    ///< [m] surface step, on the distance to the fixed point
  VolumeForm volume_form;         ///< where the scene says auto and unloads (RegistrationOptions::volume_form)
  double nodal_simulation_cell_size;  ///< [m] the mesh of that nodal form
  ElementOrder unload_elements;   ///< with that nodal form (RegistrationOptions::unload_element_order)
  double tumour_cell_size;        ///< [m] RegistrationOptions::tumour_cell_size
};
constexpr Preset kPresets[] = {
    {"fast", 0.009, 30, 1e-3, 2e-4, VolumeForm::Nodal, 0.011, ElementOrder::Linear, 0},
    {"balanced", 0.007, 60, 1e-4, 1e-4, VolumeForm::Nodal, 0.009, ElementOrder::Quadratic, 0},
    {"accurate", 0.004, 60, 1e-6, 1e-5, VolumeForm::Nodal, 0.007, ElementOrder::Quadratic, 0.004},
};

}  // namespace

RegistrationOptions preset_options(const std::string& name) {
  const Preset* p = nullptr;
  for (const Preset& q : kPresets)
    if (name == q.name) p = &q;
  if (!p) throw InputError("unknown preset '" + name + "' (fast, balanced, accurate)");
  RegistrationOptions o;
  o.preset = name;
  o.landmark.newton.max_iterations = 60;
  // 60 stopped 11 of the Table 5.1 sweep's 1 695 phantom runs from 400 Pa up while the skin was
  // still contracting, at about 0.95 a projection and 0.11 to 0.24 mm from its fixed point
  // (BENCHMARKS.md, "A stall holds the sliding"); a cap is a safety limit, not a budget.
  o.surface.max_projections = 150;
  o.surface.newton_per_projection = 1;
  o.surface.newton.max_iterations = 30;
  o.simulation_cell_size = p->simulation_cell_size;
  o.landmark.subspace.handles = p->subspace_handles;
  o.landmark.newton.gradient_rel_tolerance = p->gradient_rel_tolerance;
  o.surface.newton.gradient_rel_tolerance = p->gradient_rel_tolerance;
  o.surface.projection_tolerance = p->projection_tolerance;
  o.volume_form = p->volume_form;
  o.nodal_simulation_cell_size = p->nodal_simulation_cell_size;
  o.unload_element_order = p->unload_elements;
  o.tumour_cell_size = p->tumour_cell_size;
  return o;
}

bool takes_preset_volume_form(const Scene& scene, const RegistrationOptions& opt) {
  return scene.material.volume_form == VolumeForm::Auto && opt.volume_form == VolumeForm::Nodal &&
         scene.prone_gravity.has_value();
}

double simulation_cell_size_for(const Scene& scene, const RegistrationOptions& opt) {
  return takes_preset_volume_form(scene, opt) && opt.nodal_simulation_cell_size > 0 ? opt.nodal_simulation_cell_size
                                                                                    : opt.simulation_cell_size;
}

double tumour_cell_size_for(const Scene& scene, const RegistrationOptions& opt) {
  return scene.tumour_cell_size.value_or(opt.tumour_cell_size);
}

ElementOrder preset_unload_elements(const Scene& scene, const RegistrationOptions& opt) {
  return takes_preset_volume_form(scene, opt) && !scene.unload_element_order_stated ? opt.unload_element_order
                                                                                    : scene.material.unload_element_order;
}

std::string PlannedSteps::describe() const {
  std::string s;
  auto add = [&](bool on, const char* n) {
    if (!on) return;
    if (!s.empty()) s += " + ";
    s += n;
  };
  add(stiffness, "stiffness");  // both first: they prepare the model the other steps simulate
  add(unload, "unload");
  add(rigid_landmarks, "rigid (landmarks)");
  add(rigid_icp, "rigid (ICP)");
  add(gravity, "gravity");
  add(landmarks, "landmarks");
  add(surface, "surface");
  return s.empty() ? "none" : s;
}

PlannedSteps plan_steps(const Scene& s) {
  PlannedSteps p;
  const bool have_lm = s.landmark_anchors.size() > 0, have_rigid = s.prone_rigid && s.supine_rigid;
  const bool auto_steps = s.steps.empty();
  const std::string where = s.path + ": field 'steps': ";
  if (auto_steps || requested(s, "rigid")) {
    p.rigid_landmarks = s.landmark_anchors.size() >= 3;
    p.rigid_icp = have_rigid;
    if (!auto_steps && !p.rigid_landmarks && !p.rigid_icp)
      throw InputError(where + "'rigid' needs >= 3 landmarks or both chest_ring and supine.chest_ring");
  }
  if (requested(s, "unload") && !s.prone_gravity)
    throw InputError(where + "'unload' needs the field 'prone_gravity' (the gravity of the prone image)");
  p.unload = s.prone_gravity.has_value();
  if (s.youngs_modulus_range) {
    if (!s.prone_gravity)
      throw InputError(s.path + ": field 'material.youngs_modulus': 'estimate' needs the field 'prone_gravity'");
    if (s.landmark_anchors.size() < 3)
      throw InputError(s.path + ": field 'material.youngs_modulus': 'estimate' needs >= 3 landmarks, the scene has " +
                       std::to_string(s.landmark_anchors.size()));
    p.stiffness = true;
  }
  if (requested(s, "gravity")) p.gravity = true;
  if (auto_steps ? have_lm : requested(s, "landmarks")) {
    if (!have_lm) throw InputError(where + "'landmarks' needs the field 'landmarks'");
    p.landmarks = true;
  }
  const bool have_supine = s.supine_surface || s.supine_cloud;
  if (auto_steps ? have_supine : requested(s, "surface")) {
    if (!have_supine) throw InputError(where + "'surface' needs the field 'supine.surface' or 'supine.cloud'");
    p.surface = true;
  }
  if (!p.rigid_landmarks && !p.rigid_icp && !p.gravity && !p.landmarks && !p.surface)
    throw InputError(s.path + ": nothing to do: the scene has no landmarks, no supine surface and no rigid regions");
  if (!plan_simulates(s)) p.unload = p.stiffness = false;
  return p;
}

bool plan_simulates(const Scene& s) {
  const bool auto_steps = s.steps.empty();
  const bool have_lm = s.landmark_anchors.size() > 0, have_supine = s.supine_surface || s.supine_cloud;
  return requested(s, "gravity") || (auto_steps ? have_lm || have_supine : requested(s, "landmarks") || requested(s, "surface"));
}

bool unloads_in_preparation(const Scene& s) { return s.prone_gravity && !s.youngs_modulus_range && plan_simulates(s); }

bool needs_simulation_mesh(const Scene& scene, const RegistrationOptions& opt) {
  if (opt.simulation_cell_size <= 0) return false;
  // CGAL's meshes at cell size c have a mean edge of about 1.35 c (1.34 measured on the
  // phantom at 4.7 mm): remesh only a scene mesh clearly finer than that, away from its
  // tumours (a mesh made with prone.tumour_cell_size_mm is finer there by design). A mesh that
  // states the size it was made at is judged by it: a label mesh's refinement along its tissue
  // interfaces reads as a finer mesh (SfePy's bodies as label maps at 9 mm: mean edge 6.5 mm),
  // and its re-mesh ended farther in all 12 preset calls (BENCHMARKS.md, "A label scene keeps its mesh").
  constexpr double kEdgePerCell = 1.35, kClearlyFiner = 1.1;
  if (scene.prone_mesh_cell_size) return kEdgePerCell * *scene.prone_mesh_cell_size < kClearlyFiner * opt.simulation_cell_size;
  return mean_edge_length_away_from_tumours(scene, opt.simulation_cell_size, tumour_cell_size_for(scene, opt)) <
         kClearlyFiner * opt.simulation_cell_size;
}

std::optional<Scene> simulation_scene(const Scene& scene, const RegistrationOptions& opt) {
  if (!needs_simulation_mesh(scene, opt)) return std::nullopt;
  return with_simulation_mesh(scene, opt.simulation_cell_size, tumour_cell_size_for(scene, opt));
}

RegistrationModel prepare_model(const Scene& scene, std::vector<std::string>& warnings, const UnloadOptions& unload,
                                StepSolvers* cache) {
  RegistrationModel m = make_registration_model(scene.prone, scene.chest_wall, scene.material, scene.gravity);
  for (const auto& t : scene.tumours) {
    const int outside = add_tumour(m, t.name, t.prone);
    if (outside > 0)
      warnings.push_back("tumour '" + t.name + "': " + std::to_string(outside) +
                         " vertices lie outside the prone mesh (up to " +
                         std::to_string(m.tumours.back().embedding.max_outside_distance * 1e3) +
                         " mm); they follow the nearest tetrahedron");
  }
  for (std::string& note : assign_material_regions(m, scene.regions, scene.prone_labels, scene.prone_label_remnants))
    warnings.push_back(std::move(note));
  if (scene.tumour_youngs_modulus) {
    stiffen_tumours(m, *scene.tumour_youngs_modulus);
    if (m.stiff_tetrahedra == 0)
      warnings.push_back("tumour_material: no tetrahedron centroid lies inside a tumour; refine the mesh");
  }
  // Last: it simulates with the final materials (a stiffer tumour included).
  // Its note (a stop before converging) reaches the result's warnings with the step reports.
  if (unloads_in_preparation(scene)) unload_model(m, *scene.prone_gravity, unload, cache);
  return m;
}

RegistrationResult run_registration(const Scene& scene, const RegistrationModel& prepared, const RegistrationOptions& opt,
                                    const StepCallback& callback, StepSolvers* solvers) {
  // With the stiffness step the steps simulate a per-call copy of the model: its materials and
  // rest shape differ, its mesh, fixed vertices and cliques do not, so the cached patterns still
  // apply (the subspace, built on the rest shape, is rebuilt).
  const auto t_start = Clock::now();
  RegistrationResult r;
  r.warnings = scene.warnings;
  r.steps = plan_steps(scene);
  const bool unloaded_in_preparation = unloads_in_preparation(scene);
  if (unloaded_in_preparation != prepared.unload.has_value())
    throw InputError(unloaded_in_preparation ? "the scene gives prone_gravity but the model was prepared without the unload step"
                                             : "the model was unloaded but the scene does not ask for it here");
  // The planned steps, in order, on one state (registration_step.h).
  StepContext c(scene, prepared, opt, callback, solvers, r);
  for (const auto& step : planned_step_sequence(r.steps)) step->run(c);
  const RegistrationModel& model = c.model();
  const Rigid T = c.supine_to_model;
  const Rigid to_projector = c.to_projector;
  const Points& targets = c.targets;
  r.supine_to_model = T;
  r.volume_form = model.volume_form;
  for (const auto& rep : r.reports) {
    r.converged = r.converged && rep.converged;
    if (!rep.note.empty()) r.warnings.push_back(rep.name + " step: " + rep.note);
    if (rep.inverted > 0)
      r.warnings.push_back(rep.name + " step: " + std::to_string(rep.inverted) + " tetrahedra ended inverted" +
                           (rep.inversions_allowed ? " (the line search stalled on the inversion rule and was let invert)" : ""));
  }
  if (const std::string advice = fold_advice(model, r.reports); !advice.empty()) r.warnings.push_back(advice);
  r.seconds = since(t_start);

  // Outputs in the supine frame and figures of merit.
  const Rigid to_supine = T.inverse();
  for (size_t i = 0; i < model.tumours.size(); ++i) {
    const auto& mt = model.tumours[i];
    TumourResult tr;
    tr.name = mt.name;
    tr.registered = transform_surface(to_supine, {apply_embedding(mt.embedding, model.rest.T, r.x), mt.prone.F});
    // A tumour vertex in an inverted tetrahedron moves with a folded map: its place is not to be trusted.
    long in_inverted = 0;
    for (Eigen::Index p = 0; p < mt.embedding.tet.size(); ++p)
      if (is_inverted(r.x, model.rest.T, mt.embedding.tet(p))) ++in_inverted;
    if (in_inverted > 0)
      r.warnings.push_back("tumour " + mt.name + ": " + std::to_string(in_inverted) + " of its " +
                           std::to_string(mt.embedding.tet.size()) +
                           " vertices lie in inverted tetrahedra; its registered shape folds there");
    tr.centroid = volume_centroid(tr.registered);
    tr.volume_ratio = enclosed_volume(tr.registered) / enclosed_volume(mt.prone);
    tr.axis_ratio = principal_axis_ratio(tr.registered);
    tr.prone_axis_ratio = principal_axis_ratio(mt.prone);
    const auto& gt = scene.tumours[i].supine_ground_truth;
    if (gt) {
      tr.has_ground_truth = true;
      tr.centroid_distance = (tr.centroid - volume_centroid(*gt)).norm();
      tr.hausdorff = hausdorff_distance(tr.registered, *gt);
      tr.volume_ratio_to_truth = enclosed_volume(tr.registered) / enclosed_volume(*gt);
      tr.truth_axis_ratio = principal_axis_ratio(*gt);
      tr.rigid_centroid_distance = (to_supine * volume_centroid(mt.prone) - volume_centroid(*gt)).norm();
    }
    r.tumours.push_back(tr);
  }
  const SurfaceProjector* supine = c.supine();  // for the skin distance (and the uncertainty)
  if (opt.uncertainty.enabled) {
    if (!r.steps.surface || !supine) {
      r.uncertainty_note = "not computed: it linearises the surface step's equilibrium, and the surface step did not run";
    } else {
      // The map the surface step computed: its sliding held only if it was (it is not where the
      // alternation contracts quickly). Where the pose was solved with the deformation, the
      // skin free to slide: there the landmarks, which the inputs move, decide the pose and where
      // the skin settles, and anchors held where it settled pinned what they move (on two
      // independent bodies the held map's 95 % region held 45 of 125 noisy copies' tumours and
      // the free map's 116; BENCHMARKS.md, "The linear region with the pose free").
      SurfaceStepOptions computed = opt.surface;
      if (r.reports.back().sliding_held_from == 0 || r.pose_solved_with_surface) computed.sliding = SkinSliding::Free;
      // The pose ICP fitted on the rigid regions is a source, as uncertain as that fit says.
      std::optional<Mat6> pose_covariance;
      std::vector<std::string> notes;
      if (opt.known_supine_to_model && opt.uncertainty.sources.rigid_pose) {
        pose_covariance = opt.known_pose_covariance;
        if (!pose_covariance)
          notes.push_back("the rigid pose is held: the caller (tracking) gave it without a covariance");
      } else if (r.icp_used && !r.pose_solved_with_surface && opt.uncertainty.sources.rigid_pose) {
        pose_covariance = r.icp.pose_covariance;
        if (!pose_covariance) notes.push_back("the rigid pose is held: " + r.icp.pose_covariance_note);
      } else if (!r.pose_solved_with_surface && opt.uncertainty.sources.rigid_pose && r.steps.rigid_landmarks) {
        notes.push_back("the rigid pose is held at its solution: it came from the landmarks, not from ICP on rigid "
                        "regions, whose fit would say how well it is known");
      }
      // An estimated E is known as well as the landmarks fix it, about the estimate.
      UncertaintyOptions uopt = opt.uncertainty;
      if (r.estimated_youngs_modulus > 0 && uopt.sources.samples_youngs_modulus()) {
        char b[200];
        if (r.estimated_youngs_modulus_log_sd > 0) {
          uopt.youngs_modulus_log_sd = r.estimated_youngs_modulus_log_sd;
          std::snprintf(b, sizeof b, "E as estimated from the landmarks: sd of ln E %.3g about %.0f Pa, not the range's", r.estimated_youngs_modulus_log_sd,
                        r.estimated_youngs_modulus);
        } else {
          std::snprintf(b, sizeof b, "E estimated at %.0f Pa, but how well the landmarks fix it is not known (an end of the range): the range's sd of ln E taken",
                        r.estimated_youngs_modulus);
        }
        notes.push_back(b);
      }
      // An estimated E follows a Poisson's ratio other than the method's (the landmarks it was fitted on).
      std::optional<LandmarkStiffnessFit> fit;
      if (r.stiffness_prediction.rows() > 0) fit = LandmarkStiffnessFit{scene.landmark_anchors, r.stiffness_prediction};
      // A pose solved with the deformation stays free in the linearisation, and the landmarks
      // that share it (SurfaceGuidedStep: 3 or more) are a source.
      std::optional<FreePoseLinearisation> free_pose;
      if (r.pose_solved_with_surface) {
        free_pose = FreePoseLinearisation{to_projector, {}, Points(0, 3), opt.surface.pose_points_weight, Points(0, 3)};
        if (targets.rows() >= 3) {
          free_pose->landmarks = scene.landmark_anchors;
          free_pose->landmark_targets = transform_points(to_projector, targets);
          if (opt.surface.landmarks_on_scan) {  // as the surface step took them
            LandmarksOnScan on = landmarks_on_scan(*supine, free_pose->landmark_targets, opt.surface);
            free_pose->landmark_targets = std::move(on.targets);
            free_pose->landmark_normals = std::move(on.normals);
          }
        }
      }
      const UncertaintyResult u = linearised_tumour_uncertainty(model, r.x, *supine, to_projector, to_supine, computed,
                                                                uopt, pose_covariance, fit ? &*fit : nullptr,
                                                                free_pose ? &*free_pose : nullptr);
      for (size_t i = 0; i < r.tumours.size(); ++i) r.tumours[i].uncertainty = u.tumours[i];
      r.uncertainty_seconds = u.seconds;
      if (u.estimate_follows_poisson_ratio) {
        char b[160];
        std::snprintf(b, sizeof b, "the estimated E follows Poisson's ratio through the landmarks (d ln E / d q = %.3g)",
                      u.log_youngs_modulus_per_compliance);
        notes.push_back(b);
      }
      if (u.rest_shape_follows) {
        char b[160];
        std::snprintf(b, sizeof b, "the unloaded rest shape moves with E and Poisson's ratio (%s unload's equation: %d GMRES products, %.2f s)",
                      to_string(model.unload ? model.unload->unload.elements : ElementOrder::Linear), u.rest_response_iterations, u.rest_response_seconds);
        notes.push_back(b);
      }
      if (!u.note.empty()) notes.push_back(u.note);
      if (r.pose_solved_with_surface)
        notes.push_back(free_pose->landmarks.empty()
                            ? "the rigid pose is solved with the deformation and linearised free, the skin free to slide"
                            : "the rigid pose is solved with the deformation and linearised free, the skin free to "
                              "slide; the landmarks that share it are a source");
      if (u.estimate_follows_landmarks) {
        char b[220];
        std::snprintf(b, sizeof b,
                      "the estimated E moves with the landmarks, jointly with their direct effect (sd of ln E from "
                      "their noise %.3g; %.3g left as an independent source)",
                      u.log_sd_from_landmarks, u.log_sd_independent);
        notes.push_back(b);
      }
      if (!r.converged) notes.push_back("linearised at a state that is not converged");
      for (const auto& n : notes) r.uncertainty_note += (r.uncertainty_note.empty() ? "" : "; ") + n;
    }
  }
  if (targets.rows()) {
    std::vector<double> d;
    for (size_t i = 0; i < scene.landmark_anchors.size(); ++i)
      d.push_back((scene.landmark_anchors[i].position(r.x) - targets.row(i).transpose()).norm());
    const DistanceStats st = distance_stats(d);
    r.landmark_residual_mean = st.mean;
    r.landmark_residual_max = st.max;
  }
  if (supine) {
    std::vector<double> d;
    for (int v : model.skin) d.push_back(supine->project(to_projector * Vec3(r.x.row(v).transpose())).distance);
    const DistanceStats st = distance_stats(d);
    r.skin_distance_mean = st.mean;
    r.skin_distance_max = st.max;
  }
  check_plausibility(model, opt, r);
  return r;
}

}  // namespace btr
