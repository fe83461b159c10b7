#include <chrono>
#include <cmath>

#include "breast_tumour_registration/fem/elastic_energy.h"
#include "breast_tumour_registration/fem/gravity_energy.h"
#include "breast_tumour_registration/geometry/surface_denoising.h"
#include "breast_tumour_registration/registration/registration_step.h"
#include "breast_tumour_registration/registration/rigid_regions.h"

namespace btr {
namespace {
using Clock = std::chrono::steady_clock;
double since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

// Young's modulus from the landmarks (youngs_modulus: estimate), then the unload at it: on a
// copy of the prepared model, which stays as it was.
class StiffnessStep : public RegistrationStep {
 public:
  std::string name() const override { return "stiffness"; }
  void run(StepContext& c) const override {
    StiffnessOptions so = c.opt.stiffness;
    so.min_youngs_modulus = (*c.scene.youngs_modulus_range)[0];
    so.max_youngs_modulus = (*c.scene.youngs_modulus_range)[1];
    const StiffnessEstimate est =
        estimate_stiffness(c.prepared(), *c.scene.prone_gravity, c.scene.landmark_anchors, c.scene.landmark_supine, so, c.solvers);
    RegistrationModel m = c.prepared();
    scale_stiffness(m, est.scale);
    set_rest_shape(m, est.rest, unload_report(est.unload, c.prepared().prone), *c.scene.prone_gravity,
                   est.unload.resimulated_nodes);
    c.use_estimated_model(std::move(m));
    StepReport rep;
    rep.name = name();
    rep.converged = est.converged;
    rep.stop_reason = est.stop_reason;
    rep.outer_iterations = static_cast<int>(est.evaluations.size());
    rep.seconds = est.seconds - est.unload.seconds;  // the chosen candidate's unload is the unload step's
    rep.stiffness_youngs_modulus = est.youngs_modulus;
    rep.stiffness_misfit = est.misfit;
    if (est.at_bound) rep.note = est.stop_reason;
    c.result.reports.push_back(rep);
    c.result.estimated_youngs_modulus = est.youngs_modulus;
    c.result.stiffness_evaluations = est.evaluations;
    c.result.estimated_youngs_modulus_log_sd = est.log_sd(c.opt.uncertainty.sources.landmark_sd);
    c.result.stiffness_prediction = est.supine_prediction;
  }
};

// The unloaded rest shape: estimated once, when the model was prepared (or by the stiffness
// step at its estimate); here its report joins the result.
class UnloadStep : public RegistrationStep {
 public:
  std::string name() const override { return "unload"; }
  void run(StepContext& c) const override {
    if (c.model().unload) c.result.reports.push_back(*c.model().unload);
  }
};

// Rigid alignment. Kabsch on the landmarks is only a first guess: the landmarks sit on
// deforming skin, so their fit absorbs part of the breast's own sag. Where the landmark step
// runs, it solves the pose jointly with the deformation (gravity explains the sag); where
// rigid regions are given, ICP on them has the final word. A known pose (the node's tracking)
// replaces both.
class RigidStep : public RegistrationStep {
 public:
  std::string name() const override { return "rigid"; }
  void run(StepContext& c) const override {
    const auto t0 = Clock::now();
    RegistrationResult& r = c.result;
    Rigid T = Rigid::Identity();
    if (c.opt.known_supine_to_model) {
      T = *c.opt.known_supine_to_model;
      r.steps.rigid_landmarks = r.steps.rigid_icp = false;
    }
    Points lm_supine, lm_prone;  // landmark pairs (none when the step does not use them)
    if (r.steps.rigid_landmarks) {
      lm_supine = c.scene.landmark_supine;
      lm_prone.resize(static_cast<Eigen::Index>(c.scene.landmark_anchors.size()), 3);
      for (size_t i = 0; i < c.scene.landmark_anchors.size(); ++i)
        lm_prone.row(static_cast<Eigen::Index>(i)) = c.scene.landmark_anchors[i].position(c.model().prone).transpose();
      T = kabsch(lm_supine, lm_prone);
    }
    c.joint_pose = r.steps.rigid_landmarks && r.steps.landmarks;
    if (r.steps.rigid_icp) {
      // ICP starts from the landmark fit, the identity and the centroid-matched regions; the
      // accepted result with the lowest inlier RMS wins, unless the regions are symmetric and
      // fit turned poses equally well (then the landmarks decide, see rigid_regions.h).
      const Scene& s = c.scene;
      std::vector<Rigid> starts = {T};
      if (r.steps.rigid_landmarks) starts.push_back(Rigid::Identity());
      Rigid centred = Rigid::Identity();
      centred.translation() = (s.prone_rigid->V.colwise().mean() - s.supine_rigid->V.colwise().mean()).transpose();
      starts.push_back(centred);
      RigidRegionOptions ro = c.opt.rigid_regions;
      ro.icp = c.opt.icp;
      const RigidRegionChoice choice = align_rigid_regions(s.supine_rigid->V, s.prone_rigid->V, starts, lm_supine, lm_prone, ro);
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
                             (r.steps.rigid_landmarks ? (c.joint_pose ? "pose solved with the landmarks" : "landmark alignment")
                                                      : "identity alignment"));
      }
    } else if (r.steps.rigid_landmarks && !c.joint_pose) {
      r.warnings.push_back("rigid alignment from landmarks only (Kabsch): landmarks on deforming skin bias it; add the "
                           "landmark step, or give the rigid regions (chest_ring and supine.chest_ring) for ICP");
    }
    c.supine_to_model = T;
    if (c.scene.landmark_supine.rows()) c.targets = transform_points(T, c.scene.landmark_supine);
    r.rigid_seconds = since(t0);
  }
};

// Gravity alone (thesis Sec. 5.2.2: gravity + surface): the supine load on the rest shape.
class GravityStep : public RegistrationStep {
 public:
  std::string name() const override { return "gravity"; }
  void run(StepContext& c) const override {
    const auto t0 = Clock::now();
    const RegistrationModel& model = c.model();
    TotalEnergy energy;
    add_model_elastic_energy(energy, model);
    auto g = std::make_shared<GravityEnergy>(model.rest, model.material.density, model.gravity);
    energy.add(g);
    StepSolvers local;  // without an engine's cache: built for this call only
    NewtonSolver& solver = (c.solvers ? *c.solvers : local).gravity(model, energy.hessian_cliques());
    NewtonOptions nopt = c.opt.gravity;
    nopt.force_scale = g->total_weight();
    if (c.callback) nopt.callback = [&](const IterationInfo& it) { return c.callback("gravity", it); };
    const NewtonResult nr = solver.solve(energy, c.result.x, nopt);
    StepReport rep;
    rep.name = name();
    rep.converged = nr.converged;
    rep.stop_reason = to_string(nr.reason);
    rep.iterations = nr.iterations;
    rep.seconds = since(t0);
    rep.energy = nr.energy;
    rep.gradient_norm = nr.gradient_norm;
    rep.add_newton_profile(nr);
    c.result.reports.push_back(rep);
  }
};

// Landmark-guided deformation in the skinning subspace; without a decisive rigid region, with
// the pose as unknowns.
class LandmarkGuidedStep : public RegistrationStep {
 public:
  std::string name() const override { return "landmarks"; }
  void run(StepContext& c) const override {
    RegistrationResult& r = c.result;
    const Scene& s = c.scene;
    if (c.joint_pose && !r.icp_used) {
      Rigid moved = Rigid::Identity();
      r.reports.push_back(landmark_step(c.model(), s.landmark_anchors, c.targets, c.opt.landmark, r.x, c.callback, &moved, c.solvers));
      c.supine_to_model = moved * c.supine_to_model;
      c.targets = transform_points(moved, c.targets);
      r.pose_solved_with_landmarks = true;
      return;
    }
    r.reports.push_back(landmark_step(c.model(), s.landmark_anchors, c.targets, c.opt.landmark, r.x, c.callback, nullptr, c.solvers));
    if (!c.joint_pose) return;
    // ICP decided the pose; the joint fit (warm-started from this result) checks it.
    Points xj = r.x;
    Rigid moved = Rigid::Identity();
    const StepReport check = landmark_step(c.model(), s.landmark_anchors, c.targets, c.opt.landmark, xj, {}, &moved, c.solvers);
    r.pose_disagreement = max_displacement(moved, Rigid::Identity(), s.prone_rigid->V);
    if (r.pose_disagreement > c.opt.pose_disagreement_warning)
      r.warnings.push_back("rigid alignment: ICP on the rigid regions and the pose solved with the landmarks differ by " +
                           std::to_string(r.pose_disagreement * 1e3) + " mm on the rigid region (" +
                           (check.converged ? "" : "joint fit not converged; ") +
                           "ICP kept): check the landmark pairs and the rigid regions");
  }
};

// Surface-guided deformation with point-to-plane springs and the chest wall fixed; where the
// pose was estimated without a decisive rigid region, the whole skin refines it jointly.
class SurfaceGuidedStep : public RegistrationStep {
 public:
  std::string name() const override { return "surface"; }
  void run(StepContext& c) const override {
    RegistrationResult& r = c.result;
    const bool free_pose = (r.steps.rigid_landmarks || r.steps.rigid_icp) && !r.icp_used;
    PosePoints lm{c.scene.landmark_anchors, c.targets};
    const SurfaceProjector& supine = *c.supine();
    // Skin landmarks on the scan: their depth is the scan's (SurfaceStepOptions::landmarks_on_scan).
    if (free_pose && c.opt.surface.landmarks_on_scan && c.targets.rows() >= 3) {
      const LandmarksOnScan on = landmarks_on_scan(supine, c.targets, c.opt.surface);
      lm.targets = on.targets;
      r.landmarks_moved_onto_scan = on.moved;
    }
    r.reports.push_back(surface_step(c.model(), supine, c.opt.surface, r.x, c.callback, free_pose ? &c.to_projector : nullptr,
                                     c.targets.rows() >= 3 ? &lm : nullptr, c.solvers));
    r.pose_solved_with_surface = free_pose;
    c.supine_to_model = c.to_projector.inverse() * c.supine_to_model;
    if (c.targets.rows()) c.targets = transform_points(c.to_projector.inverse(), c.targets);
  }
};

}  // namespace

StepContext::StepContext(const Scene& s, const RegistrationModel& prepared, const RegistrationOptions& o,
                         const StepCallback& cb, StepSolvers* sv, RegistrationResult& r)
    : scene(s), opt(o), callback(cb), solvers(sv), result(r), prepared_(prepared) {
  start_positions();
}

void StepContext::use_estimated_model(RegistrationModel m) {
  estimated_ = std::move(m);
  start_positions();
}

void StepContext::start_positions() {
  const PlannedSteps& p = result.steps;
  result.x = (p.gravity || p.landmarks || p.surface) ? model().rest.V : model().prone;
}

const SurfaceProjector* StepContext::supine() {
  if (!supine_) {
    if (scene.supine_surface) {
      SurfaceMesh surface = transform_surface(supine_to_model, *scene.supine_surface);
      if (scene.supine_denoise && opt.surface.scan_denoising_min_noise > 0) {
        const double noise = estimate_surface_noise(surface);  // a rigid motion keeps it
        result.supine_noise = std::isfinite(noise) ? noise : 0.0;
        if (result.supine_noise > opt.surface.scan_denoising_min_noise) {
          surface = denoise_surface(surface, result.supine_noise);
          result.supine_denoised = true;
        }
      }
      supine_ = make_mesh_projector(surface, opt.surface.target_normals);
    } else if (scene.supine_cloud) {
      supine_ = make_cloud_projector(transform_points(supine_to_model, *scene.supine_cloud));
    }
  }
  return supine_.get();
}

std::vector<std::unique_ptr<RegistrationStep>> planned_step_sequence(const PlannedSteps& p) {
  std::vector<std::unique_ptr<RegistrationStep>> steps;
  if (p.stiffness) steps.push_back(std::make_unique<StiffnessStep>());
  if (p.unload) steps.push_back(std::make_unique<UnloadStep>());
  steps.push_back(std::make_unique<RigidStep>());
  if (p.gravity) steps.push_back(std::make_unique<GravityStep>());
  if (p.landmarks) steps.push_back(std::make_unique<LandmarkGuidedStep>());
  if (p.surface) steps.push_back(std::make_unique<SurfaceGuidedStep>());
  return steps;
}

}  // namespace btr
