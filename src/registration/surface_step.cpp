#include "breast_tumour_registration/registration/surface_step.h"

#include <chrono>
#include <limits>
#include <cmath>
#include <memory>

#include "breast_tumour_registration/base/errors.h"
#include "breast_tumour_registration/fem/elastic_energy.h"
#include "breast_tumour_registration/fem/gravity_energy.h"
#include "breast_tumour_registration/fem/plane_constraint_energy.h"
#include "breast_tumour_registration/fem/point_constraint_energy.h"
#include "breast_tumour_registration/fem/rigid_free_surface_energy.h"

namespace btr {

bool holds_projection(const Projection& c, const SurfaceStepOptions& opt) {
  if (opt.max_projection_distance > 0 && c.distance > opt.max_projection_distance) return false;
  return !(opt.reject_boundary && c.on_boundary);
}

StepReport surface_step(const RegistrationModel& model, const SurfaceProjector& supine, const SurfaceStepOptions& opt,
                        Points& x, const StepCallback& callback, Rigid* pose, const PosePoints* pose_points,
                        StepSolvers* cache) {
  const auto t0 = std::chrono::steady_clock::now();
  if (opt.max_projections < 1 || opt.newton_per_projection < 1)
    throw InputError("surface step: max_projections and newton_per_projection must be >= 1");

  TotalEnergy energy;
  add_model_elastic_energy(energy, model);
  auto gravity = std::make_shared<GravityEnergy>(model.rest, model.material.density, model.gravity);
  if (opt.gravity) energy.add(gravity);
  auto points = std::make_shared<PointConstraintEnergy>(opt.point_weight);
  auto planes = std::make_shared<PlaneConstraintEnergy>(opt.plane_weight);
  auto free_springs = std::make_shared<RigidFreeSurfaceEnergy>(opt.point_weight, opt.plane_weight);
  if (pose) {
    if (pose_points) free_springs->set_points(pose_points->anchors, pose_points->targets, opt.pose_points_weight);
    energy.add(free_springs);
  } else {
    energy.add(points);
    energy.add(planes);
  }
  StepSolvers local;  // without an engine's cache: built for this call only
  NewtonSolver& solver = (cache ? *cache : local).newton(pose ? "surface (pose free)" : "surface", model, energy.hessian_cliques());
  NewtonOptions nopt = opt.newton;
  nopt.max_iterations = opt.newton_per_projection;
  if (nopt.force_scale <= 0) nopt.force_scale = gravity->total_weight();

  StepReport rep;
  rep.name = pose ? "surface (pose free)" : "surface";
  Rigid P = Rigid::Identity();  // model frame -> the projector's frame (moves only when pose != nullptr)
  std::vector<int> held;
  Points held_y, held_n;
  rep.t_setup = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  // The held skin where the previous projection saw it (projector frame): convergence is the
  // skin no longer moving between projections. The projections themselves jitter along a
  // noisy scan (a depth camera's) without moving the skin, so their change is no criterion.
  Points skin_before = Points::Constant(static_cast<Eigen::Index>(model.skin.size()), 3, std::numeric_limits<double>::quiet_NaN());
  int offset = 0;
  bool finished = false;  // the loop ended for a reason of its own, not on the cap
  double least_motion = std::numeric_limits<double>::infinity();
  int least_at = 0;
  for (int outer = 1; outer <= opt.max_projections; ++outer) {
    const auto tp = std::chrono::steady_clock::now();
    points->clear();
    planes->clear();
    held.clear();
    double moved = 0, moved_sq = 0;
    int kept = 0;
    if (pose && outer > 1 && free_springs->size() >= 3) P = free_springs->pose(x);  // fewer: keep the last pose
    held_y.resize(static_cast<Eigen::Index>(model.skin.size()), 3);
    held_n.resize(static_cast<Eigen::Index>(model.skin.size()), 3);
    for (size_t i = 0; i < model.skin.size(); ++i) {
      const int v = model.skin[i];
      const Vec3 here = P * Vec3(x.row(v).transpose());
      const Projection c = supine.project(here);
      const double m = outer > 1 ? (here - skin_before.row(i).transpose()).norm() : std::numeric_limits<double>::infinity();
      skin_before.row(i) = here.transpose();
      if (!holds_projection(c, opt)) continue;
      // Convergence is judged on the constraints that act (a dropped projection onto a
      // scan's border slides along it as the skin moves).
      moved = std::max(moved, m);
      moved_sq += m * m;
      if (pose) {
        held_y.row(kept) = c.point.transpose();
        held_n.row(kept) = c.normal.transpose();
        held.push_back(v);
      } else {
        points->add(Anchor::vertex(v), c.point);
        planes->add(Anchor::vertex(v), c.point, c.normal);
      }
      ++kept;
    }
    if (pose) free_springs->set(held, held_y.topRows(kept), held_n.topRows(kept));
    const double moved_rms = kept ? std::sqrt(moved_sq / kept) : 0.0;
    rep.t_projection += std::chrono::duration<double>(std::chrono::steady_clock::now() - tp).count();
    rep.projection_rms_change = moved_rms;
    rep.constrained_skin = kept;
    rep.skin_vertices = static_cast<int>(model.skin.size());
    rep.projection_max_change = moved;
    if (kept == 0)
      throw InputError("surface step: no skin vertex projects inside the supine surface within " + std::to_string(opt.max_projection_distance) +
                       " m of the supine surface; is the scan aligned with the model?");
    if (callback) nopt.callback = [&](const IterationInfo& it) {
      IterationInfo shifted = it;
      shifted.iteration += offset;
      shifted.elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      return callback("surface", shifted);
    };
    // Once the projections have settled, Newton runs to its gradient criterion on them:
    // converged means both held, not that a budget ran out.
    const bool settled = outer > 1 && moved_rms <= opt.projection_tolerance;
    nopt.max_iterations = settled ? std::max(opt.newton_per_projection, opt.newton.max_iterations) : opt.newton_per_projection;
    const NewtonResult r = solver.solve(energy, x, nopt);
    offset += r.iterations;
    rep.add_newton_profile(r);
    rep.iterations += r.iterations;
    rep.outer_iterations = outer;
    rep.energy = r.energy;
    rep.gradient_norm = r.gradient_norm;
    rep.stop_reason = to_string(r.reason);
    finished = true;
    if (r.reason == StopReason::Aborted) break;
    if (r.reason == StopReason::Stalled || r.reason == StopReason::LineSearchFailed ||
        r.reason == StopReason::InvertedAfterStall) {
      rep.stop_reason = "Newton " + rep.stop_reason + " (gradient " + std::to_string(r.gradient_norm) + " N)";
      break;
    }
    if (settled) {
      rep.converged = r.converged;
      rep.stop_reason = r.converged ? "the skin stopped moving between projections and the gradient criterion held"
                                    : "the skin stopped moving between projections but Newton reached its iteration cap";
      break;
    }
    // A stall: the skin's motion has not come down for stall_projections projections (on a
    // noisy scan it settles into a jitter above the tolerance). Not converged; no use going on.
    if (outer > 1 && moved_rms < least_motion) {
      least_motion = moved_rms;
      least_at = outer;
    } else if (outer > 1 && outer - least_at >= opt.stall_projections) {
      rep.stop_reason = "stalled: the skin keeps moving " + std::to_string(moved_rms * 1e3) + " mm RMS between projections (least " +
                        std::to_string(least_motion * 1e3) + " mm, " + std::to_string(opt.stall_projections) +
                        " projections ago; tolerance " + std::to_string(opt.projection_tolerance * 1e3) + " mm): a noisy scan?";
      break;
    }
    finished = false;
  }
  if (!finished)
    rep.stop_reason = "projection cap (" + std::to_string(opt.max_projections) + ") reached with the skin still moving " +
                      std::to_string(rep.projection_rms_change * 1e3) + " mm RMS (tolerance " +
                      std::to_string(opt.projection_tolerance * 1e3) + " mm)";
  if (pose) *pose = free_springs->size() >= 3 ? free_springs->pose(x) : P;
  rep.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return rep;
}

}  // namespace btr
