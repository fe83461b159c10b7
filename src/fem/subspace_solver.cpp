#include "breast_tumour_registration/fem/subspace_solver.h"

#include <Eigen/Cholesky>
#include <chrono>
#include <cmath>

#include "breast_tumour_registration/base/errors.h"
#include "breast_tumour_registration/fem/line_search.h"
#include "breast_tumour_registration/fem/pcg.h"
#include "breast_tumour_registration/fem/tet_kinematics.h"

namespace btr {
namespace {
using Clock = std::chrono::steady_clock;
double since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }
}  // namespace

NewtonResult solve_subspace_newton(const TotalEnergy& energy, HessianAssembler& H,
                                   const Eigen::SparseMatrix<double>& basis, const Tetrahedra& tets, Points& x,
                                   const NewtonOptions& opt) {
  const auto t_start = Clock::now();
  if (basis.rows() != x.size()) throw InputError("subspace basis has the wrong number of rows");
  // Restrict the basis to the free DOFs (the assembler's ordering).
  std::vector<Eigen::Triplet<double>> trip;
  for (int k = 0; k < basis.outerSize(); ++k)
    for (Eigen::SparseMatrix<double>::InnerIterator it(basis, k); it; ++it) {
      const int v = static_cast<int>(it.row() / 3);
      if (H.is_fixed(v)) continue;
      trip.emplace_back(3 * H.free_index(v) + it.row() % 3, it.col(), it.value());
    }
  Eigen::SparseMatrix<double> U(H.num_free_dofs(), basis.cols());
  U.setFromTriplets(trip.begin(), trip.end());
  const Eigen::SparseMatrix<double> Ut = U.transpose();

  NewtonResult res;
  double E = energy.value(x);
  if (!std::isfinite(E)) throw SolverError("energy is not finite at the initial state");
  Eigen::VectorXd gr = Ut * H.gather(energy.gradient(x));
  long n_inv = tets.rows() ? count_inverted(x, tets) : 0;
  res.initial_energy = res.energy = E;
  res.initial_gradient_norm = res.gradient_norm = gr.norm();
  const double g_tol = opt.gradient_abs_tolerance + opt.gradient_rel_tolerance * std::max(gr.norm(), opt.force_scale);
  if (gr.norm() <= g_tol && opt.force_scale > 0) {
    res.reason = StopReason::GradientTolerance;
    res.converged = true;
    return res;
  }
  Points x_trial(x.rows(), 3);
  Eigen::LDLT<Eigen::MatrixXd> ldlt;
  bool have_factor = false;
  NewtonOptions local = opt;  // a stall may relax the inversion rule for the rest of the solve
  InversionGuard guard;
  bool fresh_factor = false;  // the last direction stalled on the lagged factor: refactorize
  for (int it = 1; it <= opt.max_iterations; ++it) {
    IterationInfo info;
    info.iteration = it;
    auto t0 = Clock::now();
    energy.hessian(x, opt.project_psd, H);
    const LowRankHessian low = energy.low_rank_hessian(x, H);  // H - W M W^T (usually empty)
    const Eigen::MatrixXd UtW = Ut * low.W;
    info.t_assembly = since(t0);
    // Later iterations: PCG on U^T H U (applied as three sparse products) with the lagged
    // dense factor as preconditioner; the sparse-sparse product U^T H U is formed only when
    // PCG does not reach the forcing tolerance.
    Eigen::VectorXd d;
    bool solved = false;
    if (opt.reuse_factorization && have_factor && !fresh_factor) {
      t0 = Clock::now();
      const double eta = std::min(opt.max_forcing, std::sqrt(gr.norm() / std::max(res.initial_gradient_norm, 1e-300)));
      const auto Hs = H.matrix().selfadjointView<Eigen::Lower>();
      auto apply = [&](const Eigen::VectorXd& v) {
        Eigen::VectorXd out = Ut * (Hs * (U * v));
        if (UtW.cols()) out.noalias() -= UtW * (low.M * (UtW.transpose() * v));
        return out;
      };
      int k = 0;
      solved = preconditioned_cg(apply, [&](const Eigen::VectorXd& v) { return Eigen::VectorXd(ldlt.solve(v)); }, -gr,
                                 eta, opt.max_pcg_iterations, d, k);
      info.pcg_iterations = k;
      res.pcg_iterations += k;
      info.t_solve = since(t0);
    }
    if (!solved) {
      t0 = Clock::now();
      // U^T H U by column blocks on both cores (Eigen's sparse product is sequential).
      const Eigen::Index m = U.cols(), half = m / 2;
      Eigen::MatrixXd Hr(m, m);
#pragma omp parallel for schedule(static, 1)
      for (int part = 0; part < 2; ++part) {
        const Eigen::Index c0 = part == 0 ? 0 : half, nc = part == 0 ? half : m - half;
        const Eigen::SparseMatrix<double> Ub = U.middleCols(c0, nc);
        Hr.middleCols(c0, nc) = Eigen::MatrixXd(Ut * (H.matrix() * Ub));
      }
      if (UtW.cols()) Hr.noalias() -= UtW * low.M * UtW.transpose();
      info.t_assembly += since(t0);
      t0 = Clock::now();
      const double shift = 1e-12 * std::max(Hr.diagonal().cwiseAbs().maxCoeff(), 1e-300);
      Hr.diagonal().array() += shift;
      ldlt.compute(Hr);
      have_factor = true;
      info.factorized = true;
      info.t_factorization = since(t0);
      ++res.factorizations;
      t0 = Clock::now();
      d = ldlt.solve(-gr);
      info.t_solve += since(t0);
    }
    t0 = Clock::now();
    if (!d.allFinite()) throw SolverError("subspace Newton direction is not finite");
    Eigen::VectorXd dx_full = Eigen::VectorXd::Zero(x.size());
    H.scatter_add(U * d, 1.0, dx_full);
    const Eigen::Map<const Points> dx(dx_full.data(), x.rows(), 3);
    info.t_solve += since(t0);
    const StepOutcome outcome = apply_newton_step(energy, tets, local, dx, gr.dot(d), x, x_trial, E, n_inv, info, res);
    if (outcome != StepOutcome::Taken) {
      if (!recover_from_stall(outcome, !info.factorized, local, res)) break;
      guard.arm(res, x, E, n_inv);
      fresh_factor = true;
      continue;
    }
    fresh_factor = false;
    gr = Ut * H.gather(energy.gradient(x));
    info.gradient_norm = gr.norm();
    info.elapsed = since(t_start);
    if (record_iteration(info, opt, g_tol, res)) break;
    if (info.step_norm <= opt.step_tolerance) {  // accepted, but too short to make progress
      if (!recover_from_stall(StepOutcome::Stalled, !info.factorized, local, res)) break;
      guard.arm(res, x, E, n_inv);
      fresh_factor = true;
    }
  }
  if (guard.restore_if_worse(x, E, n_inv, res, tets.rows(), opt.max_inverted_fraction_after_stall))
    gr = Ut * H.gather(energy.gradient(x));
  res.energy = E;
  res.gradient_norm = gr.norm();
  res.inverted = n_inv;
  res.seconds = since(t_start);
  return res;
}

}  // namespace btr
