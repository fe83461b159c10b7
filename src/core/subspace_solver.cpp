#include "breast_tumour_registration/core/subspace_solver.h"

#include <Eigen/Cholesky>
#include <chrono>
#include <cmath>

#include "breast_tumour_registration/core/errors.h"
#include "breast_tumour_registration/core/line_search.h"
#include "breast_tumour_registration/core/tet_kinematics.h"

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
  for (int it = 1; it <= opt.max_iterations; ++it) {
    IterationInfo info;
    info.iteration = it;
    auto t0 = Clock::now();
    energy.hessian(x, opt.project_psd, H);
    info.t_assembly = since(t0);
    // Later iterations: PCG on U^T H U (applied as three sparse products) with the lagged
    // dense factor as preconditioner; the sparse-sparse product U^T H U is formed only when
    // PCG does not reach the forcing tolerance.
    Eigen::VectorXd d;
    bool solved = false;
    if (opt.reuse_factorization && have_factor) {
      t0 = Clock::now();
      const double eta = std::min(opt.max_forcing, std::sqrt(gr.norm() / std::max(res.initial_gradient_norm, 1e-300)));
      const auto Hs = H.matrix().selfadjointView<Eigen::Lower>();
      auto apply = [&](const Eigen::VectorXd& v) { return Eigen::VectorXd(Ut * (Hs * (U * v))); };
      const Eigen::VectorXd b = -gr;
      d = ldlt.solve(b);
      Eigen::VectorXd r = b - apply(d);
      const double stop = eta * b.norm();
      int k = 0;
      if (r.norm() <= stop) {
        solved = true;
      } else {
        Eigen::VectorXd z = ldlt.solve(r), p = z;
        double rz = r.dot(z);
        for (k = 1; k <= opt.max_pcg_iterations; ++k) {
          const Eigen::VectorXd Hp = apply(p);
          const double pHp = p.dot(Hp);
          if (!(pHp > 0)) break;
          const double a = rz / pHp;
          d += a * p;
          r -= a * Hp;
          if (r.norm() <= stop) {
            solved = d.allFinite();
            break;
          }
          z = ldlt.solve(r);
          const double rz_new = r.dot(z);
          p = z + (rz_new / rz) * p;
          rz = rz_new;
        }
      }
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
    info.t_solve = since(t0);
    const double full_step = dx.rowwise().norm().maxCoeff();
    if (full_step <= opt.step_tolerance) {
      res.reason = StopReason::StepTolerance;
      res.converged = true;
      break;
    }
    t0 = Clock::now();
    const LineSearchResult ls =
        backtracking_line_search(energy, x, dx, E, gr.dot(d), n_inv, tets, line_search_options(opt), x_trial);
    info.t_line_search = since(t0);
    res.t_assembly += info.t_assembly;
    res.t_factorization += info.t_factorization;
    res.t_solve += info.t_solve;
    res.t_line_search += info.t_line_search;
    if (!ls.accepted) {
      res.reason = StopReason::LineSearchFailed;
      break;
    }
    x.swap(x_trial);
    E = ls.energy;
    n_inv = ls.inverted;
    gr = Ut * H.gather(energy.gradient(x));
    info.energy = E;
    info.gradient_norm = gr.norm();
    info.alpha = ls.alpha;
    info.step_norm = ls.alpha * full_step;
    info.inverted = n_inv;
    info.elapsed = since(t_start);
    res.iterations = it;
    res.history.push_back(info);
    if (opt.callback && !opt.callback(info)) {
      res.reason = StopReason::Aborted;
      break;
    }
    if (info.gradient_norm <= g_tol) {
      res.reason = StopReason::GradientTolerance;
      res.converged = true;
      break;
    }
    if (info.step_norm <= opt.step_tolerance) {
      res.reason = StopReason::StepTolerance;
      res.converged = true;
      break;
    }
  }
  res.energy = E;
  res.gradient_norm = gr.norm();
  res.inverted = n_inv;
  res.seconds = since(t_start);
  return res;
}

}  // namespace btr
