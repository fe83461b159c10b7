#include "breast_tumour_registration/registration/surface_step.h"

#include <chrono>
#include <limits>
#include <cmath>
#include <memory>
#include <utility>

#include "breast_tumour_registration/base/errors.h"
#include "breast_tumour_registration/fem/anderson_acceleration.h"
#include "breast_tumour_registration/fem/elastic_energy.h"
#include "breast_tumour_registration/fem/fixed_point_estimate.h"
#include "breast_tumour_registration/fem/gravity_energy.h"
#include "breast_tumour_registration/fem/spring_energy.h"
#include "breast_tumour_registration/fem/rigid_free_surface_energy.h"
#include "breast_tumour_registration/fem/tet_kinematics.h"

namespace btr {

bool holds_projection(const Projection& c, const SurfaceStepOptions& opt) {
  if (opt.max_projection_distance > 0 && c.distance > opt.max_projection_distance) return false;
  return !(opt.reject_boundary && c.on_boundary);
}

LandmarksOnScan landmarks_on_scan(const SurfaceProjector& supine, const Points& targets, const SurfaceStepOptions& opt) {
  LandmarksOnScan out{targets, Points::Zero(targets.rows(), 3), 0};
  for (Eigen::Index i = 0; i < targets.rows(); ++i) {
    const Projection c = supine.project(Vec3(targets.row(i).transpose()));
    if (!holds_projection(c, opt) || !c.point.allFinite() || !(c.normal.norm() > 0)) continue;
    out.targets.row(i) = c.point.transpose();
    out.normals.row(i) = c.normal.normalized().transpose();
    ++out.moved;
  }
  return out;
}

StepReport surface_step(const RegistrationModel& model, const SurfaceProjector& supine, const SurfaceStepOptions& opt,
                        Points& x, const StepCallback& callback, Rigid* pose, const PosePoints* pose_points,
                        StepSolvers* cache) {
  const auto t0 = std::chrono::steady_clock::now();
  if (opt.max_projections < 1 || opt.newton_per_projection < 1)
    throw InputError("surface step: max_projections and newton_per_projection must be >= 1");
  if (opt.anderson_depth < 0 || opt.floor_projections < 1 || opt.stall_projections < 1 || !(opt.projection_tolerance >= 0))
    throw InputError("surface step: anderson_depth must be >= 0, floor_projections and stall_projections >= 1, "
                     "projection_tolerance a number >= 0");
  if (!(opt.hold_contraction >= 0 && opt.hold_contraction <= 1))
    throw InputError("surface step: hold_contraction must be a number in [0, 1], got " + std::to_string(opt.hold_contraction));
  if (!(opt.inversion_stall_alpha >= 0 && opt.inversion_stall_alpha <= 1))
    throw InputError("surface step: inversion_stall_alpha must be a number in [0, 1], got " +
                     std::to_string(opt.inversion_stall_alpha));

  TotalEnergy energy;
  add_model_elastic_energy(energy, model);
  auto gravity = std::make_shared<GravityEnergy>(model.rest, model.material.density, model.gravity);
  if (opt.gravity) energy.add(gravity);
  auto springs = std::make_shared<SpringEnergy>("skin to supine surface");
  auto free_springs = std::make_shared<RigidFreeSurfaceEnergy>(opt.point_weight, opt.plane_weight);
  if (pose) {
    if (pose_points) free_springs->set_points(pose_points->anchors, pose_points->targets, opt.pose_points_weight);
    energy.add(free_springs);
  } else {
    energy.add(springs);
  }
  StepSolvers local;  // without an engine's cache: built for this call only
  NewtonSolver& solver = (cache ? *cache : local).newton(pose ? "surface (pose free)" : "surface", model, energy.hessian_cliques());
  NewtonOptions nopt = opt.newton;
  nopt.max_iterations = opt.newton_per_projection;
  nopt.inversion_stall_alpha = opt.inversion_stall_alpha;
  if (nopt.force_scale <= 0) nopt.force_scale = gravity->total_weight();

  StepReport rep;
  rep.name = pose ? "surface (pose free)" : "surface";
  rep.skin_vertices = static_cast<int>(model.skin.size());
  Rigid P = Rigid::Identity();  // model frame -> the projector's frame (moves only when pose != nullptr)
  std::vector<int> held;        // skin indices (into model.skin) the last projection holds
  std::vector<int> held_verts;  // their mesh vertices
  Points held_y(static_cast<Eigen::Index>(model.skin.size()), 3), held_n(static_cast<Eigen::Index>(model.skin.size()), 3);
  rep.t_setup = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();

  // The springs for the projections of the skin of xs (and, with a free pose, the pose that
  // best fits xs to the previous correspondences). Returns how many skin vertices they hold.
  // SkinSliding::HeldWhereSettled: from the settled state on, each held skin vertex's point
  // spring keeps (along the surface) the closest point the vertex had there: one spring with the
  // point weight to that anchor and the plane weight to the current tangent plane is the spring
  // K = w_p I + w_n n n^T with the target anchor + n w_n/(w_p + w_n) n.(closest - anchor).
  // Held from projection rep.sliding_held_from (0: not held).
  std::vector<Vec3> anchor(model.skin.size());
  std::vector<char> anchored(model.skin.size(), 0);
  auto project_at = [&](const Points& xs, bool update_pose) {
    const auto tp = std::chrono::steady_clock::now();
    springs->clear();
    held.clear();
    held_verts.clear();
    if (pose && update_pose && free_springs->size() >= 3) P = free_springs->pose(xs);  // fewer: keep the last pose
    for (size_t i = 0; i < model.skin.size(); ++i) {
      const int v = model.skin[i];
      Projection c = supine.project(P * Vec3(xs.row(v).transpose()));
      if (!holds_projection(c, opt)) continue;
      if (rep.sliding_held_from > 0) {
        if (!anchored[i]) {  // held only from now on: anchored where it is first held
          anchor[i] = c.point;
          anchored[i] = 1;
        }
        const Vec3 u = c.normal.normalized();
        c.point = anchor[i] + u * (opt.plane_weight / (opt.point_weight + opt.plane_weight) * u.dot(c.point - anchor[i]));
      }
      const Eigen::Index k = static_cast<Eigen::Index>(held.size());
      held_y.row(k) = c.point.transpose();
      held_n.row(k) = c.normal.transpose();
      held_verts.push_back(v);
      if (!pose) springs->add_point_and_plane(Anchor::vertex(v), c.point, c.normal, opt.point_weight, opt.plane_weight);
      held.push_back(static_cast<int>(i));
    }
    const Eigen::Index kept = static_cast<Eigen::Index>(held.size());
    if (pose) free_springs->set(held_verts, held_y.topRows(kept), held_n.topRows(kept));
    rep.t_projection += std::chrono::duration<double>(std::chrono::steady_clock::now() - tp).count();
    if (kept == 0)
      throw InputError("surface step: no skin vertex projects inside the supine surface within " + std::to_string(opt.max_projection_distance) +
                       " m of the supine surface; is the scan aligned with the model?");
    return static_cast<int>(kept);
  };
  // RMS and largest norm over the held skin of the rows of a - b [m].
  auto held_change = [&](const Points& a, const Points& b) {
    double s = 0, largest = 0;
    for (int i : held) {
      const double d = (a.row(model.skin[static_cast<size_t>(i)]) - b.row(model.skin[static_cast<size_t>(i)])).norm();
      s += d * d;
      largest = std::max(largest, d);
    }
    return std::make_pair(held.empty() ? 0.0 : std::sqrt(s / static_cast<double>(held.size())), largest);
  };

  // The fixed-point iteration x <- G(x): project the skin of x, one Newton step on those
  // projections (thesis Algorithm 2), with Anderson acceleration where it lowers the merit
  // (the energy with the springs of a state's own projections). Convergence bounds the distance
  // to the fixed point, not the last step: |x - x*| <= |G(x) - x| / (1 - q) for a contraction
  // q, estimated by the rate at which the residual falls (on soft tissue q is 0.8 to 0.9, so a
  // small step is far from the answer).
  const Eigen::Index dim = x.size();
  auto as_vector = [&](const Points& p) { return Eigen::Map<const Eigen::VectorXd>(p.data(), dim); };
  std::unique_ptr<AndersonAcceleration> aa;
  if (opt.anderson_depth > 0) aa = std::make_unique<AndersonAcceleration>(opt.anderson_depth);
  rep.constrained_skin = project_at(x, false);
  double merit = energy.value(x);
  const long inverted_start = count_inverted(x, model.rest.T);
  long inverted_now = inverted_start;
  Points g;
  int offset = 0;
  bool finished = false;  // the loop ended for a reason of its own, not on the cap
  double least_residual = std::numeric_limits<double>::infinity();
  int least_at = 0;
  // The first state whose step fell below the tolerance (where the thesis's criterion, and this
  // step's before issue 10, stopped): kept, and returned if going on to the fixed point fails
  // (a fold, a stall, the cap), so that the stricter criterion never leaves a worse answer.
  Points fallback;
  int fallback_at = 0;
  bool aborted = false;
  std::vector<double>& residuals = rep.projection_residuals;  // per projection [m]
  size_t residuals_since = 0;  // the first residual of the map in use (a stall's hold starts a new one)
  bool held_after_stall = false;
  // SkinSliding::HeldWhereSettled: each skin vertex's sliding held from projection `outer` on, at
  // its closest point on the scan from the state xs.
  auto hold_sliding_at = [&](const Points& xs, int outer) {
    rep.sliding_held_from = outer;
    for (size_t i = 0; i < model.skin.size(); ++i) {
      const Projection c = supine.project(P * Vec3(xs.row(model.skin[i]).transpose()));
      anchored[i] = holds_projection(c, opt);
      anchor[i] = c.point;
    }
  };
  const bool may_hold = opt.sliding == SkinSliding::HeldWhereSettled && opt.point_weight > 0;
  // How far the freely sliding skin's limit lies from xs, checked by another route than the
  // steps: at that limit the point springs (a proximal term) vanish, so it is where the energy
  // without them (elastic, gravity, point-to-plane springs on these projections and, with a free
  // pose, the landmarks) is stationary; one Newton step on that energy from xs goes most of the
  // way. The steps alone can miss a slow mode under a faster one (verify_free_limit).
  // That energy shares the step's elastic and gravity terms; only its springs are its own,
  // filled with the last projection's correspondences at each check.
  TotalEnergy limit;
  for (const auto& term : energy.terms())
    if (term != springs && term != free_springs) limit.add(term);
  auto limit_springs = std::make_shared<SpringEnergy>("skin to supine surface");
  auto limit_free_springs = std::make_shared<RigidFreeSurfaceEnergy>(0.0, opt.plane_weight);
  if (pose) {
    if (pose_points) limit_free_springs->set_points(pose_points->anchors, pose_points->targets, opt.pose_points_weight);
    limit.add(limit_free_springs);
  } else {
    limit.add(limit_springs);
  }
  auto free_limit_distance = [&](const Points& xs) {
    const Eigen::Index kept = static_cast<Eigen::Index>(held_verts.size());
    if (pose) {
      limit_free_springs->set(held_verts, held_y.topRows(kept), held_n.topRows(kept));
    } else {
      limit_springs->clear();
      for (Eigen::Index k = 0; k < kept; ++k)
        limit_springs->add_point_and_plane(Anchor::vertex(held_verts[static_cast<size_t>(k)]), Vec3(held_y.row(k).transpose()),
                                           Vec3(held_n.row(k).transpose()), 0.0, opt.plane_weight);
    }
    Points y = xs;
    NewtonOptions o = nopt;
    o.max_iterations = 1;
    o.callback = {};
    rep.add_newton_times(solver.solve(limit, y, o));  // not its inversion counts: those are the alternation's
    return held_change(y, xs).first;
  };
  for (int outer = 1; outer <= opt.max_projections; ++outer) {
    if (callback) nopt.callback = [&](const IterationInfo& it) {
      IterationInfo shifted = it;
      shifted.iteration += offset;
      shifted.elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      return callback("surface", shifted);
    };
    g = x;
    nopt.max_iterations = opt.newton_per_projection;
    NewtonResult r = solver.solve(energy, g, nopt);
    offset += r.iterations;
    rep.add_newton_profile(r);
    rep.iterations += r.iterations;
    rep.outer_iterations = outer;
    rep.energy = r.energy;
    rep.gradient_norm = r.gradient_norm;
    rep.stop_reason = to_string(r.reason);
    finished = true;
    if (r.reason == StopReason::Aborted) {
      aborted = true;
      x = g;
      break;
    }
    if (r.reason == StopReason::Stalled || r.reason == StopReason::LineSearchFailed || r.reason == StopReason::InvertedAfterStall) {
      x = g;
      rep.stop_reason = "Newton " + rep.stop_reason + " (gradient " + std::to_string(r.gradient_norm) + " N)";
      break;
    }
    // A stall let this Newton invert elements: the rest of the step may too (one alternation is
    // one solve; a fresh rule per projection would stall it again). The projection's change,
    // cut short by the rule, is no sign of settling: it is not counted.
    if (r.inversions_allowed && nopt.forbid_new_inversions) {
      nopt.forbid_new_inversions = false;  // rep.inversions_allowed is set by add_newton_profile
      if (outer < opt.max_projections) {
        x = g;
        if (aa) aa->reset();
        rep.constrained_skin = project_at(x, true);
        merit = energy.value(x);
        inverted_now = r.inverted;
        finished = false;
        continue;
      }
    }
    // The fixed-point residual and the contraction between this iterate and the last; the
    // bound needs two contraction estimates (the first step, from the landmark step's state,
    // contracts far more than the slow tangential relaxation after it).
    const auto [residual, largest_change] = held_change(g, x);
    residuals.push_back(residual);
    // The contraction and the distance to the fixed point (fixed_point_estimate.h: one-step
    // ratios, or two-step ones where the residuals alternate large and small).
    // (After a stall's hold the map changed: only its own residuals measure its contraction.)
    const FixedPointEstimate fp = estimate_fixed_point(
        std::vector<double>(residuals.begin() + static_cast<std::ptrdiff_t>(residuals_since), residuals.end()));
    const double q_hat = fp.contraction, distance = fp.distance;
    rep.projection_max_change = largest_change;
    rep.contraction = q_hat;
    rep.fixed_point_distance = distance;
    if (fallback_at == 0 && outer > 1 && residual <= opt.projection_tolerance) {
      fallback = g;
      fallback_at = outer;
    }
    // The alternation's floor: on a polyhedral surface the closest points switch between
    // faces, and the skin ends jittering by a few hundredths of a millimetre per projection
    // without a contraction to measure. When the residual has not reached a new low for
    // floor_projections and none of them moved more than the tolerance, the skin jitters
    // within the tolerance of where it settles (no closer fixed point to estimate).
    double floor_spread = std::numeric_limits<double>::infinity();
    if (static_cast<int>(residuals.size()) > opt.floor_projections && residual >= least_residual) {
      floor_spread = 0;
      for (size_t k = residuals.size() - static_cast<size_t>(opt.floor_projections) - 1; k < residuals.size(); ++k)
        floor_spread = std::max(floor_spread, residuals[k]);
      if (outer - least_at < opt.floor_projections) floor_spread = std::numeric_limits<double>::infinity();
    }
    const bool bounded = distance <= opt.projection_tolerance;
    const bool at_floor = floor_spread <= opt.projection_tolerance;
    bool settled = bounded || at_floor;
    // A free skin read as settled: is its limit where the steps say? Where it lies farther than
    // the tolerance, the steps missed a slow slide (with a free pose on the ring-free phantom at
    // 600 Pa, unloaded, they read 0.081 mm with the skin 0.162 mm RMS from the limit): the skin
    // is not settled; with HeldWhereSettled its sliding is held here, as for a creep, and the
    // held alternation goes on to its own fixed point.
    // (The report keeps the first check that found the limit beyond, else the last check.)
    if (settled && opt.verify_free_limit && rep.sliding_held_from == 0 && opt.point_weight > 0 && !held_verts.empty()) {
      const double d = free_limit_distance(g);
      if (!rep.free_limit_missed) {
        rep.free_limit_distance = d;
        rep.free_limit_checked_at = outer;
      }
      if (d > opt.projection_tolerance) {
        settled = false;
        rep.free_limit_missed = true;
        if (may_hold && outer < opt.max_projections) {
          hold_sliding_at(g, outer);
          residuals_since = residuals.size();
          least_residual = std::numeric_limits<double>::infinity();
          least_at = outer;
        }
      }
    }
    if (settled) {
      // Settled: Newton runs to its gradient criterion on these projections, so converged
      // means both held, not that a budget ran out.
      nopt.max_iterations = std::max(opt.newton_per_projection, opt.newton.max_iterations);
      r = solver.solve(energy, g, nopt);
      offset += r.iterations;
      rep.add_newton_profile(r);
      rep.iterations += r.iterations;
      rep.energy = r.energy;
      rep.gradient_norm = r.gradient_norm;
      rep.converged = r.converged;
      if (!bounded) rep.fixed_point_distance = floor_spread;
      const std::string how = bounded ? "the skin settled (estimated " + std::to_string(distance * 1e3) +
                                            " mm RMS from the fixed point, contraction " + std::to_string(q_hat) + ")"
                                      : "the skin settled to its jitter floor (" + std::to_string(floor_spread * 1e3) +
                                            " mm RMS per projection at most over the last " + std::to_string(opt.floor_projections + 1) +
                                            " projections)";
      rep.stop_reason = r.converged ? how + " and the gradient criterion held"
                        : r.reason == StopReason::MaxIterations
                            ? how + " but Newton reached its iteration cap (gradient " + std::to_string(r.gradient_norm) + " N)"
                            : how + " but Newton on those projections stopped: " + to_string(r.reason) + " (gradient " +
                                  std::to_string(r.gradient_norm) + " N)";
      x = g;
      break;
    }
    // A stall: the residual has not come down for stall_projections projections (on a noisy
    // scan it settles into a jitter). Not converged; no use going on.
    if (residual < least_residual) {
      least_residual = residual;
      least_at = outer;
    }
    // What a stall of a freely sliding skin calls for: its sliding held where it is, as for a
    // creep, and the alternation goes on, with a least residual and a contraction of its own.
    // On a scan misaligned with the chest wall (the thesis's method without its rigid step) the
    // free skin slid on along the scan by 0.2 to 0.8 mm per projection, growing, from 600 Pa up;
    // held, it contracts within a few projections (BENCHMARKS.md, "A stall holds the sliding").
    // Only a held skin that stalls is a stall.
    if (outer - least_at >= opt.stall_projections && may_hold && rep.sliding_held_from == 0 && outer < opt.max_projections) {
      hold_sliding_at(g, outer);
      held_after_stall = true;
      residuals_since = residuals.size();
      least_residual = std::numeric_limits<double>::infinity();
      least_at = outer;
    }
    if (outer - least_at >= opt.stall_projections) {
      x = g;
      rep.stop_reason = "stalled: the skin keeps moving " + std::to_string(residual * 1e3) + " mm RMS per projection (least " +
                        std::to_string(least_residual * 1e3) + " mm, " + std::to_string(outer - least_at) +
                        " projections ago; tolerance " + std::to_string(opt.projection_tolerance * 1e3) +
                        " mm from the fixed point)" +
                        (rep.sliding_held_from > 0 ? std::string(" with its sliding held: a noisy scan, or a model that cannot reach it?")
                                                   : std::string(": a noisy scan?"));
      break;
    }
    finished = false;
    if (outer == opt.max_projections) {
      x = g;
      break;
    }
    // A creep: the skin moves less than the tolerance per projection but slides on along the
    // scan at a contraction of hold_contraction or more. With HeldWhereSettled its sliding is
    // held from here: the anchors are this state's closest points.
    if (rep.sliding_held_from == 0 && may_hold && fallback_at > 0 && q_hat >= opt.hold_contraction) hold_sliding_at(g, outer);
    // The next iterate: Anderson's proposal where it lowers the merit without inverting more
    // elements than the plain step, else the plain step (and the history starts over).
    bool accepted = false;
    if (aa) {
      const Eigen::VectorXd proposal = aa->next(as_vector(x), as_vector(g));
      if (aa->columns() > 0 && proposal.allFinite()) {
        Points cand = Eigen::Map<const Points>(proposal.data(), x.rows(), 3);
        for (Eigen::Index v = 0; v < x.rows(); ++v)  // fixed vertices stay (their rows agree in x and g anyway)
          if (model.fixed[static_cast<size_t>(v)]) cand.row(v) = g.row(v);
        const long inv = count_inverted(cand, model.rest.T);
        if (inv <= std::max(r.inverted, inverted_now)) {
          rep.constrained_skin = project_at(cand, true);
          const double m = energy.value(cand);
          if (std::isfinite(m) && m <= merit) {
            x = cand;
            merit = m;
            inverted_now = inv;
            accepted = true;
            ++rep.accelerated_projections;
          }
        }
        if (!accepted) aa->reset();
      }
    }
    if (!accepted) {
      x = g;
      rep.constrained_skin = project_at(x, true);
      merit = energy.value(x);
      inverted_now = r.inverted;
    }
  }
  if (!finished)
    rep.stop_reason = "projection cap (" + std::to_string(opt.max_projections) + ") reached, the skin still moving " +
                      std::to_string(rep.projection_rms_change() * 1e3) + " mm RMS per projection (estimated " +
                      (std::isfinite(rep.fixed_point_distance) ? std::to_string(rep.fixed_point_distance * 1e3) + " mm" : std::string("an unknown distance")) +
                      " from the fixed point; tolerance " + std::to_string(opt.projection_tolerance * 1e3) + " mm)";
  if (held_after_stall)
    rep.stop_reason += "; the skin's sliding held from projection " + std::to_string(rep.sliding_held_from) +
                       ", where it had stalled sliding freely";
  if (rep.free_limit_missed)
    rep.stop_reason += std::string("; at projection ") + std::to_string(rep.free_limit_checked_at) +
                       " the steps read the skin as settled but its free limit lay " +
                       std::to_string(rep.free_limit_distance * 1e3) + " mm RMS away" +
                       (rep.sliding_held_from == rep.free_limit_checked_at ? ", so its sliding was held there"
                                                                           : ", and the alternation went on");
  // A limit with tetrahedra inverted that the step's start did not have. Within Newton's own
  // allowance (max_inverted_fraction_after_stall of the mesh: a few elements under the skin
  // passing a nearly flat state where soft tissue meets stiff springs) it is the answer the
  // criteria found, and the count is reported; returning the earlier state instead was measured
  // to cost accuracy on both bodies (BENCHMARKS.md, "Inverted elements at the limit"). Beyond
  // the allowance the mesh folded to meet the scan: not converged (the earlier state is returned
  // where there is one).
  // (x is the last Newton's result on every exit, so its count is rep.inverted.)
  const long newly_inverted = rep.inverted - inverted_start;
  if (rep.converged && newly_inverted > 0) {
    const double allowance = nopt.max_inverted_fraction_after_stall * static_cast<double>(model.rest.T.rows());
    if (static_cast<double>(newly_inverted) <= allowance) {
      rep.stop_reason += "; " + std::to_string(rep.inverted) + " tetrahedra ended inverted (" + std::to_string(newly_inverted) +
                         " new, within the allowance of " + std::to_string(static_cast<long>(allowance)) + ")";
    } else {
      rep.converged = false;
      rep.stop_reason += ", but " + std::to_string(rep.inverted) + " tetrahedra ended inverted (" +
                         std::to_string(newly_inverted) + " new, beyond the allowance of " +
                         std::to_string(static_cast<long>(allowance)) + "): the mesh folded";
    }
  }
  if (!rep.converged && !aborted && fallback_at > 0) {
    x = fallback;
    rep.constrained_skin = project_at(x, true);
    nopt.max_iterations = std::max(opt.newton_per_projection, opt.newton.max_iterations);
    const long inverted_there = count_inverted(x, model.rest.T);
    const NewtonResult r = solver.solve(energy, x, nopt);
    rep.add_newton_profile(r);
    rep.iterations += r.iterations;
    std::string there = to_string(r.reason);
    if (r.inverted > inverted_there) {  // a stall that was let invert: that state as it was instead
      x = fallback;
      rep.inverted = inverted_there;
      there += "; it inverted elements, so the state is kept without it";
    }
    rep.energy = energy.value(x);
    rep.gradient_norm = r.gradient_norm;
    rep.stop_reason += "; kept the state of projection " + std::to_string(fallback_at) +
                       ", where the skin first moved less than the tolerance per projection (Newton there: " + there + ")";
    rep.note = "the surface step did not reach its fixed point; the result is the state where the skin first moved less than " +
               std::to_string(opt.projection_tolerance * 1e3) + " mm per projection";
  }
  if (pose) *pose = free_springs->size() >= 3 ? free_springs->pose(x) : P;
  rep.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return rep;
}

}  // namespace btr
