#include "breast_tumour_registration/fem/newton_solver.h"

#include <Eigen/CholmodSupport>
#include <chrono>
#include <cmath>
#include <limits>

#include "breast_tumour_registration/base/errors.h"
#include "breast_tumour_registration/fem/blas_threads.h"
#include "breast_tumour_registration/fem/heap_retention.h"
#include "breast_tumour_registration/fem/line_search.h"
#include "breast_tumour_registration/fem/pcg.h"
#include "breast_tumour_registration/fem/tet_kinematics.h"

namespace btr {
namespace {

using Clock = std::chrono::steady_clock;
double since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

// The state at which a stall let the line search invert elements (recover_from_stall). A solve
// that then ends with more than max_inverted_fraction_after_stall of its tetrahedra newly
// inverted folded the mesh to meet its constraints (landmarks pulled through the chest
// wall): the state is restored and the solve reported as InvertedAfterStall. One that ends
// within it keeps its result, and the count is reported (soft tissue whose prone shape
// stands in for the rest shape: 1 to 6 of 7.1k elements at E = 400 Pa).
struct InversionGuard {
  bool armed = false;
  Points x;
  double energy = 0;
  long inverted = 0;
  // Records the state the first time res.inversions_allowed is set.
  void arm(const NewtonResult& res, const Points& x_now, double E, long n_inv);
  // At the end of a solve: restores the recorded state when x has more than
  // max_fraction x n_tets inversions beyond it; returns true when it did.
  bool restore_if_worse(Points& x_now, double& E, long& n_inv, NewtonResult& res, long n_tets, double max_fraction) const;
};

LineSearchOptions line_search_options(const NewtonOptions& opt);

// Takes the step dx (#V by 3) with the line search from x (energy E, n_inv inverted
// tetrahedra), updating x, E, n_inv, the iteration's alpha / step norm / line-search time and
// the result's time totals.
StepOutcome apply_newton_step(const TotalEnergy& energy, const InversionCheck& inversions, const NewtonOptions& opt,
                              const Eigen::Ref<const Points>& dx, double slope, Points& x, Points& x_trial, double& E,
                              long& n_inv, IterationInfo& info, NewtonResult& res) {
  const double full_step = dx.rowwise().norm().maxCoeff();
  if (full_step <= opt.step_tolerance) return StepOutcome::TooSmall;
  const auto t0 = Clock::now();
  const LineSearchResult ls = backtracking_line_search(energy, x, dx, E, slope, n_inv, inversions, line_search_options(opt), x_trial);
  info.t_line_search = since(t0);
  res.t_assembly += info.t_assembly;
  res.t_factorization += info.t_factorization;
  res.t_solve += info.t_solve;
  res.t_line_search += info.t_line_search;
  if (!ls.accepted) return StepOutcome::NoDecrease;
  x.swap(x_trial);
  E = ls.energy;
  n_inv = ls.inverted;
  info.energy = E;
  info.alpha = ls.alpha;
  info.step_norm = ls.alpha * full_step;
  info.inverted = n_inv;
  info.inversion_limited = ls.inversion_limited;
  return StepOutcome::Taken;
}

// Records an accepted iteration in `res` (history, totals), calls the callback and applies
// the gradient criterion; returns true when the solve should stop (reason and converged set).
bool record_iteration(const IterationInfo& info, const NewtonOptions& opt, double gradient_tolerance, NewtonResult& res) {
  res.iterations = info.iteration;
  res.energy = info.energy;
  res.gradient_norm = info.gradient_norm;
  res.inverted = info.inverted;
  res.history.push_back(info);
  if (opt.callback && !opt.callback(info)) {
    res.reason = StopReason::Aborted;
    return true;
  }
  if (info.gradient_norm <= gradient_tolerance) {
    res.reason = StopReason::GradientTolerance;
    res.converged = true;
    return true;
  }
  return false;
}

void InversionGuard::arm(const NewtonResult& res, const Points& x_now, double E, long n_inv) {
  if (armed || !res.inversions_allowed) return;
  armed = true;
  x = x_now;
  energy = E;
  inverted = n_inv;
}

bool InversionGuard::restore_if_worse(Points& x_now, double& E, long& n_inv, NewtonResult& res, long n_tets,
                                      double max_fraction) const {
  if (!armed || static_cast<double>(n_inv - inverted) <= max_fraction * static_cast<double>(n_tets)) return false;
  x_now = x;
  E = energy;
  n_inv = inverted;
  res.reason = StopReason::InvertedAfterStall;
  res.converged = false;
  return true;
}

LineSearchOptions line_search_options(const NewtonOptions& opt) {
  LineSearchOptions l;
  l.max_steps = opt.max_line_search_steps;
  l.armijo = opt.armijo;
  l.forbid_new_inversions = opt.forbid_new_inversions;
  return l;
}

}  // namespace

std::string to_string(StopReason r) {
  switch (r) {
    case StopReason::GradientTolerance: return "gradient tolerance reached";
    case StopReason::StepTolerance: return "full Newton step below the step tolerance";
    case StopReason::Stalled: return "stalled: line-search steps below the step tolerance with the gradient above its tolerance";
    case StopReason::InvertedAfterStall:
      return "stalled: every step inverted an element, and letting them invert folded the mesh; the last uninverted "
             "state is kept";
    case StopReason::MaxIterations: return "maximum iterations reached";
    case StopReason::LineSearchFailed: return "line search found no decrease";
    case StopReason::Aborted: return "aborted by callback";
  }
  return "unknown";
}

bool recover_from_stall(StepOutcome outcome, bool direction_was_lagged, NewtonOptions& opt, NewtonResult& res) {
  if (direction_was_lagged) return true;  // first: a fresh factorization
  if (outcome != StepOutcome::TooSmall && opt.forbid_new_inversions) {
    // Second: let the line search invert elements. The stable Neo-Hookean energy is defined
    // there, and soft tissue pulled by stiff springs otherwise freezes on one nearly flat
    // element (measured: E = 400 Pa, surface step stalled at 590 N, tumour 13.8 mm off;
    // with inversions allowed it converges, 0.77 mm). The result reports the inverted count.
    opt.forbid_new_inversions = false;
    res.inversions_allowed = true;
    return true;
  }
  switch (outcome) {
    case StepOutcome::TooSmall:  // the exact Newton step: the minimum is within step_tolerance
      res.reason = StopReason::StepTolerance;
      res.converged = true;
      break;
    case StepOutcome::NoDecrease:
      res.reason = StopReason::LineSearchFailed;
      res.converged = false;
      break;
    default:  // a damped step too short to make progress
      res.reason = StopReason::Stalled;
      res.converged = false;
  }
  return false;
}

NewtonResult newton_minimize(const TotalEnergy& energy, HessianAssembler& H, const InversionCheck& inversions,
                             NewtonLinearSolve& linear, Points& x, const NewtonOptions& opt) {
  const auto t_start = Clock::now();
  NewtonResult res;
  auto inverted = [&](const Points& p) { return inversions.count(p); };

  double E = energy.value(x);
  if (!std::isfinite(E)) throw SolverError("energy is not finite at the initial state (NaN or Inf positions?)");
  Eigen::VectorXd g = linear.reduce(H.gather(energy.gradient(x)));
  long n_inv = inverted(x);
  res.initial_energy = res.energy = E;
  res.initial_gradient_norm = res.gradient_norm = g.norm();
  res.inverted = n_inv;
  const double g_tol = opt.gradient_abs_tolerance +
                       opt.gradient_rel_tolerance * std::max(res.initial_gradient_norm, opt.force_scale);
  if (H.num_free_dofs() == 0 || res.gradient_norm <= opt.gradient_abs_tolerance ||
      (opt.force_scale > 0 && res.gradient_norm <= g_tol)) {
    res.reason = StopReason::GradientTolerance;
    res.converged = true;
    res.seconds = since(t_start);
    return res;
  }

  Points x_trial(x.rows(), 3);
  NewtonOptions local = opt;  // a stall may relax the inversion rule for the rest of the solve
  InversionGuard guard;
  bool fresh_factor = false;  // the last direction stalled on the lagged factor: refactorize
  // Near the solution the unprojected Hessian (positive definite there as a whole, although
  // compressed elements are indefinite on their own) restores quadratic convergence; the
  // projected one converges linearly in that tail. Any sign of trouble switches back.
  bool exact = false;
  double exact_retry_below = std::numeric_limits<double>::infinity();  // after a failed try: wait for progress
  auto leave_exact = [&] {
    exact = false;
    exact_retry_below = 0.5 * g.norm();
  };
  for (int it = 1; it <= opt.max_iterations; ++it) {
    IterationInfo info;
    info.iteration = it;

    auto t0 = Clock::now();
    energy.hessian(x, opt.project_psd && !exact, H);
    const LowRankHessian low = energy.low_rank_hessian(x, H);  // H - W M W^T (usually empty)
    linear.set_hessian(H, low);
    info.t_assembly = since(t0);

    Eigen::VectorXd d;
    bool solved = false;
    if (opt.reuse_factorization && linear.has_factor() && !fresh_factor) {
      t0 = Clock::now();
      const double eta = std::min(opt.max_forcing, std::sqrt(g.norm() / std::max(res.initial_gradient_norm, 1e-300)));
      solved = linear.lagged_solve(-g, eta, opt.max_pcg_iterations, d, info.pcg_iterations);
      info.t_solve = since(t0);
      res.pcg_iterations += info.pcg_iterations;
    }
    if (!solved) {
      t0 = Clock::now();
      if (!linear.factorize(!exact, res.regularizations)) {  // the exact Hessian is not positive definite: project again
        leave_exact();
        energy.hessian(x, true, H);
        linear.set_hessian(H, low);
        linear.factorize(true, res.regularizations);
      }
      ++res.factorizations;
      info.factorized = true;
      info.t_factorization = since(t0);
      t0 = Clock::now();
      d = linear.solve(-g);
      info.t_solve += since(t0);
    }
    if (!d.allFinite()) throw SolverError("Newton direction is not finite");

    // Full step as vertex displacements.
    Eigen::VectorXd dx_full = Eigen::VectorXd::Zero(x.size());
    H.scatter_add(linear.expand(d), 1.0, dx_full);
    const Eigen::Map<const Points> dx(dx_full.data(), x.rows(), 3);
    const StepOutcome outcome = apply_newton_step(energy, inversions, local, dx, g.dot(d), x, x_trial, E, n_inv, info, res);
    if (outcome != StepOutcome::Taken) {
      if (exact) {  // retry on the projected Hessian before calling it a stall
        leave_exact();
        fresh_factor = true;
        continue;
      }
      if (!recover_from_stall(outcome, !info.factorized, local, res)) break;
      guard.arm(res, x, E, n_inv);
      fresh_factor = true;
      continue;
    }
    fresh_factor = false;
    const double g_before = g.norm();
    g = linear.reduce(H.gather(energy.gradient(x)));
    // Near the solution (full step accepted, |g| below 1% of the load) or where the projected
    // Hessian only converges linearly (|g| not halved by a full step).
    if (opt.project_psd && opt.exact_hessian_near_solution && linear.supports_exact_hessian() && !exact &&
        info.alpha == 1.0 && g.norm() < exact_retry_below &&
        (g.norm() <= 1e-2 * std::max(res.initial_gradient_norm, opt.force_scale) || g.norm() > 0.5 * g_before))
      exact = true;
    info.gradient_norm = g.norm();
    info.elapsed = since(t_start);
    if (record_iteration(info, opt, g_tol, res)) break;
    if (guard.armed && opt.abandon_inverted_fraction > 0 &&
        static_cast<double>(n_inv - guard.inverted) > opt.abandon_inverted_fraction * static_cast<double>(inversions.elements())) {
      guard.restore_if_worse(x, E, n_inv, res, inversions.elements(), 0);  // folding: end here, on the guard's state
      g = linear.reduce(H.gather(energy.gradient(x)));
      break;
    }
    if (local.forbid_new_inversions && info.inversion_limited && info.alpha <= opt.inversion_stall_alpha) {
      // The inversion rule, not the energy, cut the step short: let the line search invert
      // from here (the guard keeps this state if the solve then folds the mesh).
      local.forbid_new_inversions = false;
      res.inversions_allowed = true;
      guard.arm(res, x, E, n_inv);
      fresh_factor = true;
      continue;
    }
    if (info.step_norm <= opt.step_tolerance) {  // accepted, but too short to make progress
      if (exact) {
        leave_exact();
        fresh_factor = true;
        continue;
      }
      if (!recover_from_stall(StepOutcome::Stalled, !info.factorized, local, res)) break;
      guard.arm(res, x, E, n_inv);
      fresh_factor = true;
    }
  }
  if (guard.restore_if_worse(x, E, n_inv, res, inversions.elements(), opt.max_inverted_fraction_after_stall))
    g = linear.reduce(H.gather(energy.gradient(x)));
  res.energy = E;
  res.gradient_norm = g.norm();
  res.inverted = n_inv;
  res.seconds = since(t_start);
  return res;
}

namespace {

// The full-space solve: CHOLMOD supernodal Cholesky of the free-DOF Hessian, the symbolic
// analysis once per pattern; a low-rank part by the Woodbury identity.
class SparseCholeskySolve : public NewtonLinearSolve {
 public:
  SparseCholeskySolve() {
    use_single_threaded_blas();
    keep_freed_heap_memory();
    // A failed factorization is expected (the unprojected Hessian tried near the solution) and
    // handled by the driver; CHOLMOD's own "not positive definite" lines on stderr would only alarm.
    llt_.cholmod().print = 0;
  }
  Eigen::VectorXd reduce(const Eigen::VectorXd& g_free) const override { return g_free; }
  Eigen::VectorXd expand(const Eigen::VectorXd& d) const override { return d; }
  void set_hessian(const HessianAssembler& H, const LowRankHessian& low) override {
    H_ = &H.matrix();
    low_ = &low;
  }
  bool has_factor() const override { return have_factor_; }
  bool lagged_solve(const Eigen::VectorXd& rhs, double eta, int max_iterations, Eigen::VectorXd& d, int& its) override {
    const auto Hs = H_->selfadjointView<Eigen::Lower>();
    auto apply = [&](const Eigen::VectorXd& v) {
      Eigen::VectorXd out = Hs * v;
      if (low_->W.cols()) out.noalias() -= low_->W * (low_->M * (low_->W.transpose() * v));
      return out;
    };
    return preconditioned_cg(apply, [&](const Eigen::VectorXd& v) { return Eigen::VectorXd(llt_.solve(v)); }, rhs, eta,
                             max_iterations, d, its);
  }
  bool factorize(bool may_shift, int& regularizations) override {
    if (!analyzed_) {
      llt_.analyzePattern(*H_);
      analyzed_ = true;
    }
    // The projected Hessian is PSD; with few constraints it can be singular, so a growing
    // diagonal shift is tried before giving up.
    llt_.setShift(0);
    llt_.factorize(*H_);
    if (llt_.info() != Eigen::Success && !may_shift) return false;
    double shift = 0;
    const double diag_scale = H_->diagonal().cwiseAbs().maxCoeff();
    while (llt_.info() != Eigen::Success) {
      shift = shift == 0 ? 1e-10 * std::max(diag_scale, 1e-30) : shift * 100;
      if (!std::isfinite(shift) || shift > 1e2 * std::max(diag_scale, 1e-30)) {
        have_factor_ = false;
        throw SolverError("Hessian could not be factorized even with a diagonal shift (non-finite entries?)");
      }
      llt_.setShift(shift);
      llt_.factorize(*H_);
      ++regularizations;
    }
    have_factor_ = true;
    return true;
  }
  Eigen::VectorXd solve(const Eigen::VectorXd& rhs) override {
    Eigen::VectorXd d = llt_.solve(rhs);
    if (low_->W.cols()) {
      // Woodbury: (H - W M W^T)^-1 = H^-1 + Z (I - M W^T Z)^-1 M Z^T with Z = H^-1 W.
      const Eigen::MatrixXd Z = llt_.solve(low_->W);
      const Eigen::MatrixXd K = Eigen::MatrixXd::Identity(low_->M.rows(), low_->M.rows()) - low_->M * (low_->W.transpose() * Z);
      d += Z * K.fullPivLu().solve(low_->M * (Z.transpose() * rhs));
    }
    return d;
  }
  void forget_factor() override { have_factor_ = false; }

 private:
  Eigen::CholmodSupernodalLLT<Eigen::SparseMatrix<double>, Eigen::Lower> llt_;
  bool analyzed_ = false;
  bool have_factor_ = false;  // llt_ holds a factor of some earlier Hessian (same pattern)
  const Eigen::SparseMatrix<double>* H_ = nullptr;
  const LowRankHessian* low_ = nullptr;
};

}  // namespace

struct NewtonSolver::Impl {
  SparseCholeskySolve linear;
};

NewtonSolver::NewtonSolver(std::shared_ptr<HessianAssembler> assembler, InversionCheck inversions)
    : assembler_(std::move(assembler)), inversions_(std::move(inversions)), impl_(std::make_unique<Impl>()) {}

NewtonSolver::~NewtonSolver() = default;

void NewtonSolver::forget_factor() { impl_->linear.forget_factor(); }

NewtonResult NewtonSolver::solve(const TotalEnergy& energy, Points& x, const NewtonOptions& opt) {
  return newton_minimize(energy, *assembler_, inversions_, impl_->linear, x, opt);
}

}  // namespace btr
