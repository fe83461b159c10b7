#include "breast_tumour_registration/registration/registration_pipeline.h"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "breast_tumour_registration/base/errors.h"
#include "breast_tumour_registration/base/units.h"
#include "breast_tumour_registration/fem/elastic_energy.h"
#include "breast_tumour_registration/fem/gravity_energy.h"
#include "breast_tumour_registration/geometry/metrics.h"
#include "breast_tumour_registration/geometry/surface_attachment.h"
#include "breast_tumour_registration/geometry/validation.h"
#include "breast_tumour_registration/registration/material_regions.h"
#include "breast_tumour_registration/registration/rigid_regions.h"
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

RegistrationOptions preset_options(const std::string& name) {
  RegistrationOptions o;
  o.preset = name;
  // A preset is a set of tolerances (what "converged" means for it) and a simulation mesh;
  // the iteration caps are generous safety limits, reported as not converged when hit.
  // Mesh sizes from the measured Pareto front (BENCHMARKS.md): on the phantom the accuracy
  // saturates from a 7 mm simulation mesh on.
  o.landmark.newton.max_iterations = 60;
  o.surface.max_projections = 60;
  o.surface.newton_per_projection = 1;
  o.surface.newton.max_iterations = 30;
  if (name == "fast") {
    o.simulation_cell_size = 0.009;
    o.landmark.subspace.handles = 30;
    o.landmark.newton.gradient_rel_tolerance = 1e-3;
    o.surface.newton.gradient_rel_tolerance = 1e-3;
    o.surface.projection_tolerance = 2e-4;
  } else if (name == "balanced") {
    o.simulation_cell_size = 0.007;
    o.landmark.subspace.handles = 60;
    o.landmark.newton.gradient_rel_tolerance = 1e-4;
    o.surface.newton.gradient_rel_tolerance = 1e-4;
    o.surface.projection_tolerance = 1e-4;
  } else if (name == "accurate") {  // the scene's own mesh
    o.landmark.subspace.handles = 60;
    o.landmark.newton.gradient_rel_tolerance = 1e-6;
    o.surface.newton.gradient_rel_tolerance = 1e-6;
    o.surface.projection_tolerance = 1e-5;
  } else {
    throw InputError("unknown preset '" + name + "' (fast, balanced, accurate)");
  }
  return o;
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
  return p;
}

bool needs_simulation_mesh(const Scene& scene, const RegistrationOptions& opt) {
  if (opt.simulation_cell_size <= 0) return false;
  // CGAL's meshes at cell size c have a mean edge of about 1.35 c (1.34 measured on the
  // phantom at 4.7 mm): remesh only a scene mesh clearly finer than that.
  return mean_edge_length(scene.prone) < 1.1 * opt.simulation_cell_size;
}

std::optional<Scene> simulation_scene(const Scene& scene, const RegistrationOptions& opt) {
  if (!needs_simulation_mesh(scene, opt)) return std::nullopt;
  return with_simulation_mesh(scene, opt.simulation_cell_size);
}

RegistrationModel prepare_model(const Scene& scene, std::vector<std::string>& warnings, const UnloadOptions& unload) {
  RegistrationModel m = make_registration_model(scene.prone, scene.chest_wall, scene.material, scene.gravity);
  for (const auto& t : scene.tumours) {
    const int outside = add_tumour(m, t.name, t.prone);
    if (outside > 0)
      warnings.push_back("tumour '" + t.name + "': " + std::to_string(outside) +
                         " vertices lie outside the prone mesh (up to " +
                         std::to_string(m.tumours.back().embedding.max_outside_distance * 1e3) +
                         " mm); they follow the nearest tetrahedron");
  }
  assign_material_regions(m, scene.regions, scene.prone_labels);
  if (scene.tumour_youngs_modulus) {
    stiffen_tumours(m, *scene.tumour_youngs_modulus);
    if (m.stiff_tetrahedra == 0)
      warnings.push_back("tumour_material: no tetrahedron centroid lies inside a tumour; refine the mesh");
  }
  // Last: it simulates with the final materials (a stiffer tumour included).
  // Its note (a stop before converging) reaches the result's warnings with the step reports.
  if (scene.prone_gravity && !scene.youngs_modulus_range) unload_model(m, *scene.prone_gravity, unload);
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
  const bool unloaded_in_preparation = r.steps.unload && !r.steps.stiffness;
  if (unloaded_in_preparation != prepared.unload.has_value())
    throw InputError(unloaded_in_preparation ? "the scene gives prone_gravity but the model was prepared without the unload step"
                                             : "the model was unloaded but the scene does not ask for it here");
  // 0. Stiffness (then the unload at it): on a copy of the prepared model, which stays as it was.
  std::optional<RegistrationModel> estimated;
  if (r.steps.stiffness) {
    StiffnessOptions so = opt.stiffness;
    so.min_youngs_modulus = (*scene.youngs_modulus_range)[0];
    so.max_youngs_modulus = (*scene.youngs_modulus_range)[1];
    const StiffnessEstimate est =
        estimate_stiffness(prepared, *scene.prone_gravity, scene.landmark_anchors, scene.landmark_supine, so);
    estimated = prepared;
    scale_stiffness(*estimated, est.scale);
    set_rest_shape(*estimated, est.rest, unload_report(est.unload, prepared.prone));
    StepReport rep;
    rep.name = "stiffness";
    rep.converged = est.converged;
    rep.stop_reason = est.stop_reason;
    rep.outer_iterations = static_cast<int>(est.evaluations.size());
    rep.seconds = est.seconds - est.unload.seconds;  // the chosen candidate's unload is the unload step's
    rep.stiffness_youngs_modulus = est.youngs_modulus;
    rep.stiffness_misfit = est.misfit;
    if (est.at_bound) rep.note = est.stop_reason;
    r.reports.push_back(rep);
    r.estimated_youngs_modulus = est.youngs_modulus;
    r.stiffness_evaluations = est.evaluations;
  }
  const RegistrationModel& model = estimated ? *estimated : prepared;
  // From the rest shape: stress-free, so every step travels rest -> supine only (from the prone
  // shape over an unloaded rest, a soft breast would have to swing through prone -> supine).
  // Without a deforming step the answer is the prone shape moved rigidly.
  r.x = (r.steps.gravity || r.steps.landmarks || r.steps.surface) ? model.rest.V : model.prone;
  if (model.unload) r.reports.push_back(*model.unload);  // done once, when the model was prepared

  // 1. Rigid alignment. Kabsch on the landmarks is only a first guess: the landmarks sit on
  // deforming skin, so their fit absorbs part of the breast's own sag. Where the landmark step
  // runs, it solves the pose jointly with the deformation (gravity explains the sag); where
  // rigid regions are given, ICP on them has the final word.
  auto t0 = Clock::now();
  Rigid T = Rigid::Identity();
  if (opt.known_supine_to_model) {
    T = *opt.known_supine_to_model;
    r.steps.rigid_landmarks = r.steps.rigid_icp = false;
  }
  Points lm_supine, lm_prone;  // landmark pairs for the rigid step (none when it does not use them)
  if (r.steps.rigid_landmarks) {
    lm_supine = scene.landmark_supine;
    lm_prone.resize(scene.landmark_anchors.size(), 3);
    for (size_t i = 0; i < scene.landmark_anchors.size(); ++i)
      lm_prone.row(i) = scene.landmark_anchors[i].position(model.prone).transpose();
    T = kabsch(lm_supine, lm_prone);
  }
  const bool joint_pose = r.steps.rigid_landmarks && r.steps.landmarks;
  if (r.steps.rigid_icp) {
    // ICP starts from the landmark fit, the identity and the centroid-matched regions; the
    // accepted result with the lowest inlier RMS wins, unless the regions are symmetric and
    // fit turned poses equally well (then the landmarks decide, see rigid_regions.h).
    std::vector<Rigid> starts = {T};
    if (r.steps.rigid_landmarks) starts.push_back(Rigid::Identity());
    Rigid centred = Rigid::Identity();
    centred.translation() = (scene.prone_rigid->V.colwise().mean() - scene.supine_rigid->V.colwise().mean()).transpose();
    starts.push_back(centred);
    RigidRegionOptions ro = opt.rigid_regions;
    ro.icp = opt.icp;
    const RigidRegionChoice choice =
        align_rigid_regions(scene.supine_rigid->V, scene.prone_rigid->V, starts, lm_supine, lm_prone, ro);
    r.icp = choice.icp;
    r.rigid_distinct_poses = choice.distinct_poses;
    r.rigid_decided_by_landmarks = choice.decided_by_landmarks;
    r.rigid_pose_undecided = choice.undecided;
    r.rigid_note = choice.note;
    // A symmetric ring that the landmarks resolve is information; one nothing resolves is a warning.
    if (choice.undecided) r.warnings.push_back("rigid alignment: " + choice.note);
    if (r.icp.accepted) {
      T = r.icp.transform;
      r.icp_used = true;
    } else {
      r.warnings.push_back("rigid alignment: " + r.icp.message + " from every initial guess; keeping the " +
                           (r.steps.rigid_landmarks ? (joint_pose ? "pose solved with the landmarks" : "landmark alignment")
                                                    : "identity alignment"));
    }
  } else if (r.steps.rigid_landmarks && !joint_pose) {
    r.warnings.push_back("rigid alignment from landmarks only (Kabsch): landmarks on deforming skin bias it; add the "
                         "landmark step, or give the rigid regions (chest_ring and supine.chest_ring) for ICP");
  }
  r.rigid_seconds = since(t0);

  // 2. Optional gravity pre-step (thesis Sec. 5.2.2: gravity + surface).
  if (r.steps.gravity) {
    const auto tg = Clock::now();
    TotalEnergy energy;
    add_model_elastic_energy(energy, model);
    auto g = std::make_shared<GravityEnergy>(model.rest, model.material.density, model.gravity);
    energy.add(g);
    StepSolvers local;
    NewtonSolver& solver = (solvers ? *solvers : local).newton("gravity", model, energy.hessian_cliques());
    NewtonOptions nopt = opt.gravity;
    nopt.force_scale = g->total_weight();
    if (callback) nopt.callback = [&](const IterationInfo& it) { return callback("gravity", it); };
    const NewtonResult nr = solver.solve(energy, r.x, nopt);
    StepReport rep;
    rep.name = "gravity";
    rep.converged = nr.converged;
    rep.stop_reason = to_string(nr.reason);
    rep.iterations = nr.iterations;
    rep.seconds = since(tg);
    rep.energy = nr.energy;
    rep.gradient_norm = nr.gradient_norm;
    rep.add_newton_profile(nr);
    r.reports.push_back(rep);
  }
  // 3. Landmark-guided step; without a decisive rigid region, with the pose as unknowns.
  Points targets = scene.landmark_supine.rows() ? transform_points(T, scene.landmark_supine) : Points();
  if (r.steps.landmarks) {
    if (joint_pose && !r.icp_used) {
      Rigid moved = Rigid::Identity();
      r.reports.push_back(landmark_step(model, scene.landmark_anchors, targets, opt.landmark, r.x, callback, &moved, solvers));
      T = moved * T;
      targets = transform_points(moved, targets);
      r.pose_solved_with_landmarks = true;
    } else {
      r.reports.push_back(landmark_step(model, scene.landmark_anchors, targets, opt.landmark, r.x, callback, nullptr, solvers));
      if (joint_pose) {
        // ICP decided the pose; the joint fit (warm-started from this result) checks it.
        Points xj = r.x;
        Rigid moved = Rigid::Identity();
        const StepReport check = landmark_step(model, scene.landmark_anchors, targets, opt.landmark, xj, {}, &moved, solvers);
        r.pose_disagreement = max_displacement(moved, Rigid::Identity(), scene.prone_rigid->V);
        if (r.pose_disagreement > opt.pose_disagreement_warning)
          r.warnings.push_back("rigid alignment: ICP on the rigid regions and the pose solved with the landmarks differ by " +
                               std::to_string(r.pose_disagreement * 1e3) + " mm on the rigid region (" +
                               (check.converged ? "" : "joint fit not converged; ") +
                               "ICP kept): check the landmark pairs and the rigid regions");
      }
    }
  }
  // The supine surface in the model frame as the rigid step left it, as a projector (AABB
  // tree or kd-tree + normals), built once for the surface step and the skin-distance figure.
  std::unique_ptr<SurfaceProjector> supine;
  if (scene.supine_surface) supine = make_mesh_projector(transform_surface(T, *scene.supine_surface), opt.surface.target_normals);
  else if (scene.supine_cloud) supine = make_cloud_projector(transform_points(T, *scene.supine_cloud));

  // 4. Surface-guided step; where the pose was estimated without a decisive rigid region, the
  // whole skin refines it jointly with the deformation.
  Rigid to_projector = Rigid::Identity();  // model frame -> the projector's frame
  if (r.steps.surface) {
    const bool free_pose = (r.steps.rigid_landmarks || r.steps.rigid_icp) && !r.icp_used;
    PosePoints lm{scene.landmark_anchors, targets};
    r.reports.push_back(surface_step(model, *supine, opt.surface, r.x, callback, free_pose ? &to_projector : nullptr,
                                     targets.rows() >= 3 ? &lm : nullptr, solvers));
    r.pose_solved_with_surface = free_pose;
    T = to_projector.inverse() * T;
    if (targets.rows()) targets = transform_points(to_projector.inverse(), targets);
  }
  r.supine_to_model = T;
  for (const auto& rep : r.reports) {
    r.converged = r.converged && rep.converged;
    if (!rep.note.empty()) r.warnings.push_back(rep.name + " step: " + rep.note);
    if (rep.inverted > 0)
      r.warnings.push_back(rep.name + " step: " + std::to_string(rep.inverted) + " tetrahedra ended inverted" +
                           (rep.inversions_allowed ? " (the line search stalled on the inversion rule and was let invert)" : ""));
  }
  r.seconds = since(t_start);

  // Outputs in the supine frame and figures of merit.
  const Rigid to_supine = T.inverse();
  for (size_t i = 0; i < model.tumours.size(); ++i) {
    const auto& mt = model.tumours[i];
    TumourResult tr;
    tr.name = mt.name;
    tr.registered = transform_surface(to_supine, {apply_embedding(mt.embedding, model.rest.T, r.x), mt.prone.F});
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
  if (opt.uncertainty.enabled) {
    if (!r.steps.surface || !supine) {
      r.uncertainty_note = "not computed: it linearises the surface step's equilibrium, and the surface step did not run";
    } else {
      const UncertaintyResult u =
          linearised_tumour_uncertainty(model, r.x, *supine, to_projector, to_supine, opt.surface, opt.uncertainty);
      for (size_t i = 0; i < r.tumours.size(); ++i) r.tumours[i].uncertainty = u.tumours[i];
      r.uncertainty_seconds = u.seconds;
      std::vector<std::string> notes;
      if (!u.note.empty()) notes.push_back(u.note);
      if (r.pose_solved_with_surface)
        notes.push_back("the rigid pose is held at its solution, but here it is solved with the deformation: on such a "
                        "body (no rigid region) the linear region came out 3 to 5 times smaller than sampled "
                        "re-registrations; use --uncertainty sampling");
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
