#include "breast_tumour_registration/fem/unloaded_shape.h"

#include <chrono>
#include <cmath>
#include <limits>
#include <memory>

#include <Eigen/QR>

#include "breast_tumour_registration/base/errors.h"
#include "breast_tumour_registration/base/units.h"
#include "breast_tumour_registration/fem/forward_gravity.h"
#include "breast_tumour_registration/fem/tet_kinematics.h"

namespace btr {
namespace {

double max_row_norm(const Points& d) { return d.rows() ? d.rowwise().norm().maxCoeff() : 0.0; }

}  // namespace

UnloadResult estimate_unloaded_shape(const UnloadProblem& pb, const UnloadOptions& opt) {
  const auto t0 = std::chrono::steady_clock::now();
  if (!pb.loaded) throw InputError("unload: no loaded mesh");
  if (pb.volume_form == VolumeForm::Auto) throw InputError("unload: resolve the volume form first");
  if (!(opt.tolerance > 0) || opt.max_iterations < 1 || opt.anderson_depth < 0)
    throw InputError("unload: tolerance must be > 0, max_iterations >= 1 and anderson_depth >= 0");
  if (opt.max_forward_solves < 0) throw InputError("unload: the forward-solve budget must be >= 0 (0: none)");
  if (!(pb.gravity.norm() > 0)) throw InputError("unload: the imaging gravity must not be zero");
  const TetMesh& loaded = *pb.loaded;
  const Eigen::Index nv = loaded.V.rows();
  std::vector<bool> fixed(nv, false);
  for (int v : pb.fixed) {
    if (v < 0 || v >= nv) throw InputError("unload: fixed vertex " + std::to_string(v) + " out of range");
    fixed[v] = true;
  }
  const Points& xp = loaded.V;

  ForwardGravity phi(loaded.T, nv, pb.fixed, pb.materials, pb.material_of, pb.volume_form, pb.nodal_element_share,
                     pb.density, opt.forward, pb.solver);
  UnloadResult res;
  res.elements = opt.forward.element_order;
  int first = 0;  // Newton iterations of the first converged forward solve: the cost unit
  const std::string budget_spent = "forward-solve budget (" + std::to_string(opt.max_forward_solves) + ") spent";
  auto spent = [&] { return opt.max_forward_solves > 0 && res.iterations >= opt.max_forward_solves; };
  // phi(X) under gravity g; x the start, then the equilibrium. false: it failed (x unchanged),
  // or the budget was spent (not attempted).
  auto forward = [&](const Points& X, Points& x, const Vec3& g) {
    if (spent()) return false;
    const int before = phi.newton_iterations();
    bool ok = true;
    try {
      phi.solve(X, g, x);
    } catch (const SolverError&) {
      ok = false;
    }
    if (ok && first == 0) first = phi.newton_iterations() - before;
    ++res.iterations;
    return ok;
  };

  // The fixed point at `scale` x the imaging gravity from the first estimate X0, to `tolerance`.
  struct Stage {
    Points X, x;  // the best estimate and its equilibrium
    Points nodes; // quadratic elements: every node of that equilibrium
    bool started = false, converged = false;
    double best = std::numeric_limits<double>::infinity();
    std::vector<double> history;
    std::string reason;
  };
  auto fixed_point = [&](double scale, const Points& X0, double tolerance) {
    Stage st;
    const Vec3 g = scale * pb.gravity;
    Points X = X0, x;
    // The first forward solve starts from the loaded shape (the target), else from the estimate itself.
    for (const bool warm : {true, false}) {
      x = warm ? xp : X;
      if (forward(X, x, g)) {
        st.started = true;
        break;
      }
    }
    if (!st.started) {
      st.reason = spent() ? budget_spent : "the first forward solve did not converge from the first estimate";
      return st;
    }
    st.X = X;
    st.x = x;
    // Anderson mixing on G(X) = X + f(X), f(X) = x_p - phi(X), over free DOFs (fixed rows of f are 0).
    std::vector<Eigen::VectorXd> dX, dF;
    Eigen::VectorXd X_prev, f_prev;
    for (int k = 1;; ++k) {
      const Points f = xp - x;
      const double mismatch = max_row_norm(f);
      st.history.push_back(mismatch);
      if (mismatch < st.best) {
        st.best = mismatch;
        st.X = X;
        st.x = x;
        if (opt.forward.element_order == ElementOrder::Quadratic) st.nodes = phi.quadratic_nodes();  // x's solve was the last
      }
      if (mismatch < tolerance) {
        st.converged = true;
        st.reason = "re-simulating reproduces the loaded shape within " + format_mm(tolerance, 3);
        break;
      }
      if (k >= opt.max_iterations) {
        st.reason = "forward-solve cap (" + std::to_string(opt.max_iterations) + ") reached, mismatch " + format_mm(st.best, 3);
        break;
      }
      if (k > 5 && mismatch > 10 * st.best) {
        st.reason = "diverging: the mismatch grew from " + format_mm(st.best, 3) + " to " + format_mm(mismatch, 3);
        break;
      }
      const Eigen::VectorXd Xv = as_vector(X), fv = as_vector(f);
      if (X_prev.size()) {
        dX.push_back(Xv - X_prev);
        dF.push_back(fv - f_prev);
        if (static_cast<int>(dX.size()) > opt.anderson_depth) {
          dX.erase(dX.begin());
          dF.erase(dF.begin());
        }
      }
      X_prev = Xv;
      f_prev = fv;
      Eigen::VectorXd next = Xv + fv;
      const bool accelerated = opt.anderson_depth > 0 && !dF.empty();
      if (accelerated) {
        Eigen::MatrixXd Fm(fv.size(), static_cast<Eigen::Index>(dF.size())), Xm(fv.size(), static_cast<Eigen::Index>(dX.size()));
        for (size_t j = 0; j < dF.size(); ++j) {
          Fm.col(static_cast<Eigen::Index>(j)) = dF[j];
          Xm.col(static_cast<Eigen::Index>(j)) = dX[j];
        }
        const Eigen::VectorXd gamma = Fm.colPivHouseholderQr().solve(fv);
        next -= (Xm + Fm) * gamma;
      }
      // The candidate, then (if its forward solve fails or its rest shape inverts an element) the
      // plain fixed-point step with the Anderson history dropped (unless the candidate was that
      // step already), then that step halved.
      bool moved = false;
      int tried = 0, inverting = 0;
      for (int attempt = 0; attempt < 5 && !moved; ++attempt) {
        if (attempt == 1) {
          if (!accelerated) continue;
          dX.clear();
          dF.clear();
          next = Xv + fv;
        } else if (attempt > 1) {
          next = Xv + std::pow(0.5, attempt - 1) * fv;
        }
        ++tried;
        Points Xc = Eigen::Map<const Points>(next.data(), nv, 3);
        for (Eigen::Index v = 0; v < nv; ++v)
          if (fixed[v]) Xc.row(v) = xp.row(v);
        if (count_inverted(Xc, loaded.T) > 0) {
          ++inverting;
          continue;
        }
        // Warm start: the last equilibrium's displacement applied to the new rest shape; if that
        // stalls, a cold start from the rest shape itself.
        for (const bool warm : {true, false}) {
          Points xc = warm ? Points(Xc + (x - X)) : Xc;
          if (!forward(Xc, xc, g)) continue;
          X = Xc;
          x = xc;
          moved = true;
          break;
        }
      }
      if (!moved) {
        // A step whose rest shape inverts an element is not solved at all: where every one does,
        // no forward solve failed; the estimate cannot move on without an inverted rest element.
        if (spent())
          st.reason = budget_spent + ", mismatch " + format_mm(st.best, 3);
        else if (inverting == tried)
          st.reason = "every step towards the next estimate (the plain one, halved down to 1/8) inverts a rest element "
                      "(the rest shape this model needs may have inverted elements); mismatch " + format_mm(st.best, 3);
        else
          st.reason = "no forward solve converged from the next estimate, nor from a plain or halved step (" +
                      std::to_string(inverting) + " of the " + std::to_string(tried) +
                      " steps invert a rest element); mismatch " + format_mm(st.best, 3);
        break;
      }
    }
    return st;
  };

  // Directly: from the loaded shape under the opposite gravity ("inverse gravity"), which lifts
  // a breast near its unloaded shape; the loaded shape itself when that solve fails.
  Points X0 = xp;
  if (pb.initial_rest) {
    if (pb.initial_rest->rows() != nv || !pb.initial_rest->allFinite())
      throw InputError("unload: the initial rest shape has " + std::to_string(pb.initial_rest->rows()) +
                       " finite vertices, the mesh " + std::to_string(nv));
    X0 = *pb.initial_rest;
    if (count_inverted(X0, loaded.T) > 0) X0 = xp;
  }
  if (!pb.initial_rest) {
    Points lifted = xp;
    if (forward(xp, lifted, -pb.gravity)) {
      // A forward solve may end with a few elements inverted (its allowance); a rest shape may
      // not, so such a lift is no start (the estimate would keep them, and every later solve
      // on that rest shape would refuse it).
      if (count_inverted(lifted, loaded.T) == 0) X0 = lifted;
      res.inverse_gravity_lift = max_row_norm(lifted - xp);
    }
  }
  Stage result = fixed_point(1.0, X0, opt.tolerance);
  // Else load continuation of the inverse problem: the unloaded shape for a growing fraction of
  // the gravity, each stage started from the last two extrapolated (a soft breast whose prone
  // sag is too large for one step).
  if (!result.converged && opt.max_stages > 0 && !spent()) {
    ++res.continuation_stages;  // the direct attempt
    double s = 0, s_prev = 0, ds = opt.first_stage_fraction;
    Points X_s = xp, X_prev = xp;
    std::string failure;
    while (s < 1 && res.continuation_stages <= opt.max_stages && !spent()) {
      const double next = std::min(1.0, s + ds);
      Points init = X_s;
      if (s > 0) {
        init = X_s + ((next - s) / (s - s_prev)) * (X_s - X_prev);
        if (count_inverted(init, loaded.T) > 0) init = X_s;
      } else {
        Points lifted = xp;
        if (forward(xp, lifted, -next * pb.gravity) && count_inverted(lifted, loaded.T) == 0) init = lifted;
      }
      Stage st = fixed_point(next, init, next < 1 ? opt.stage_tolerance : opt.tolerance);
      ++res.continuation_stages;
      if (st.converged) {
        s_prev = s;
        X_prev = X_s;
        X_s = st.X;
        s = next;
        ds *= 1.5;
        if (s >= 1) result = st;
      } else {
        failure = "at " + std::to_string(static_cast<int>(std::lround(next * 100))) + " % of the gravity: " + st.reason;
        ds = 0.5 * (next - s);  // half the stage that failed (ds may reach past the full gravity)
        if (ds < 1.0 / 64) break;
      }
    }
    if (!result.converged)
      result.reason = (spent() ? budget_spent + ": " : std::string()) + "neither directly nor by load continuation (" +
                      std::to_string(res.continuation_stages) + " stages, reached " +
                      std::to_string(static_cast<int>(std::lround(s * 100))) + " % of the gravity" +
                      (failure.empty() ? "" : "; last failure " + failure) + "): " + result.reason;
  }
  res.load_steps = phi.load_steps();
  res.newton_iterations = phi.newton_iterations();
  res.converged = result.converged;
  res.stop_reason = result.reason;
  res.mismatch_history = result.history;
  if (!result.started) {  // nothing verified: the loaded shape is the only honest estimate
    res.rest = xp;
    res.resimulated = xp;
    res.max_mismatch = std::numeric_limits<double>::infinity();
  } else {
    res.rest = result.X;
    res.resimulated = result.x;
    res.resimulated_nodes = result.nodes;
    res.max_mismatch = result.best;
  }
  res.forward_solve_equivalents = first > 0 ? static_cast<double>(res.newton_iterations) / first : 0.0;
  res.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return res;
}

}  // namespace btr
