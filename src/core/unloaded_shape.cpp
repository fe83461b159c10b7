#include "breast_tumour_registration/core/unloaded_shape.h"

#include <chrono>
#include <cmath>
#include <limits>
#include <memory>

#include <Eigen/QR>

#include "breast_tumour_registration/core/errors.h"
#include "breast_tumour_registration/core/gravity_energy.h"
#include "breast_tumour_registration/core/tet_kinematics.h"
#include "breast_tumour_registration/core/units.h"

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
  if (!(pb.gravity.norm() > 0)) throw InputError("unload: the imaging gravity must not be zero");
  const TetMesh& loaded = *pb.loaded;
  const Eigen::Index nv = loaded.V.rows();
  std::vector<bool> fixed(nv, false);
  for (int v : pb.fixed) {
    if (v < 0 || v >= nv) throw InputError("unload: fixed vertex " + std::to_string(v) + " out of range");
    fixed[v] = true;
  }
  const Points& xp = loaded.V;

  // One assembler (and so one symbolic analysis) for every forward solve: the pattern does not
  // depend on the rest positions.
  TetMesh rest{xp, loaded.T};
  std::shared_ptr<HessianAssembler> assembler;
  std::unique_ptr<NewtonSolver> solver;
  auto forward = [&](const Points& X, Points& x, UnloadResult& res, double gravity_sign = 1.0) {
    rest.V = X;
    TotalEnergy energy;
    add_elastic_energy(energy, rest, pb.materials, pb.material_of, pb.volume_form);
    auto g = std::make_shared<GravityEnergy>(rest, pb.density, gravity_sign * pb.gravity);
    energy.add(g);
    if (!assembler) {
      assembler = std::make_shared<HessianAssembler>(static_cast<int>(nv), loaded.T, fixed, energy.hessian_cliques());
      solver = std::make_unique<NewtonSolver>(assembler, loaded.T);
    }
    NewtonOptions nopt = opt.newton;
    if (nopt.force_scale <= 0) nopt.force_scale = g->total_weight();
    for (Eigen::Index v = 0; v < nv; ++v)
      if (fixed[v]) x.row(v) = X.row(v);
    const NewtonResult nr = solver->solve(energy, x, nopt);
    res.newton_iterations += nr.iterations;
    if (!nr.converged)
      throw SolverError("unload: a forward gravity solve stopped without converging (" + to_string(nr.reason) + ")");
    return nr.iterations;
  };

  UnloadResult res;
  // The first estimate: the loaded shape under the opposite gravity ("inverse gravity"), which
  // lifts a soft breast near its unloaded shape; the loaded shape itself when that fails.
  Points X = xp, x = xp;
  int first = 0;
  try {
    Points lifted = xp;
    first = forward(xp, lifted, res, -1.0);
    X = lifted;
  } catch (const SolverError&) {
    X = xp;
  }
  // Its forward solve starts from the loaded shape (the target), else from the estimate itself.
  bool started = false;
  for (const bool warm : {true, false}) {
    x = warm ? xp : X;
    try {
      const int n = forward(X, x, res);
      if (first == 0) first = n;
      started = true;
      break;
    } catch (const SolverError&) {
    }
  }
  if (!started) {
    res.rest = X;
    res.resimulated = x;
    res.max_mismatch = max_row_norm(xp - x);
    res.stop_reason = "the first forward solve did not converge from the inverse-gravity estimate (too soft?)";
    res.iterations = 1;
    res.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    return res;
  }
  Points best_X = X, best_x = x;
  double best = std::numeric_limits<double>::infinity();
  // Anderson mixing on G(X) = X + f(X), f(X) = x_p - phi(X), over free DOFs (fixed rows of f are 0).
  std::vector<Eigen::VectorXd> dX, dF;
  Eigen::VectorXd X_prev, f_prev;
  for (int k = 1;; ++k) {
    const Points f = xp - x;
    const double mismatch = max_row_norm(f);
    res.mismatch_history.push_back(mismatch);
    res.iterations = k;
    if (mismatch < best) {
      best = mismatch;
      best_X = X;
      best_x = x;
    }
    if (mismatch < opt.tolerance) {
      res.converged = true;
      res.stop_reason = "re-simulating reproduces the loaded shape within " + format_mm(opt.tolerance, 3);
      break;
    }
    if (k >= opt.max_iterations) {
      res.stop_reason = "forward-solve cap (" + std::to_string(opt.max_iterations) + ") reached, mismatch " + format_mm(best, 3);
      break;
    }
    if (k > 5 && mismatch > 10 * best) {
      res.stop_reason = "diverging: the mismatch grew from " + format_mm(best, 3) + " to " + format_mm(mismatch, 3) +
                        " (too soft for this fixed point?)";
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
    if (opt.anderson_depth > 0 && !dF.empty()) {
      Eigen::MatrixXd Fm(fv.size(), static_cast<Eigen::Index>(dF.size())), Xm(fv.size(), static_cast<Eigen::Index>(dX.size()));
      for (size_t j = 0; j < dF.size(); ++j) {
        Fm.col(static_cast<Eigen::Index>(j)) = dF[j];
        Xm.col(static_cast<Eigen::Index>(j)) = dX[j];
      }
      const Eigen::VectorXd gamma = Fm.colPivHouseholderQr().solve(fv);
      next -= (Xm + Fm) * gamma;
    }
    // The candidate, then (if its forward solve fails or its rest shape inverts an element) the
    // plain fixed-point step with the Anderson history dropped, then that step halved.
    bool moved = false;
    for (int attempt = 0; attempt < 5 && !moved; ++attempt) {
      if (attempt == 1) {
        dX.clear();
        dF.clear();
        next = Xv + fv;
      } else if (attempt > 1) {
        next = Xv + std::pow(0.5, attempt - 1) * fv;
      }
      Points Xc = Eigen::Map<const Points>(next.data(), nv, 3);
      for (Eigen::Index v = 0; v < nv; ++v)
        if (fixed[v]) Xc.row(v) = xp.row(v);
      if (count_inverted(Xc, loaded.T) > 0) continue;
      // Warm start: the last equilibrium's displacement applied to the new rest shape; if that
      // stalls, a cold start from the rest shape itself.
      for (const bool warm : {true, false}) {
        Points xc = warm ? Points(Xc + (x - X)) : Xc;
        try {
          forward(Xc, xc, res);
        } catch (const SolverError&) {
          continue;
        }
        X = Xc;
        x = xc;
        moved = true;
        break;
      }
    }
    if (!moved) {
      res.stop_reason = "no forward solve converged from the next estimate, nor from a plain or halved step; mismatch " +
                        format_mm(best, 3);
      break;
    }
  }
  res.rest = best_X;
  res.resimulated = best_x;
  res.max_mismatch = best;
  res.forward_solve_equivalents = first > 0 ? static_cast<double>(res.newton_iterations) / first : 0.0;
  res.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return res;
}

}  // namespace btr
