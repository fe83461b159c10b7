// Quasi-static Newton solver (thesis Sec. 3.2): minimizes a TotalEnergy over the free
// vertices with a PSD-projected Hessian, CHOLMOD supernodal Cholesky (symbolic analysis
// once per solver, numeric factorization per iteration) and a backtracking line search.
// One driver (newton_minimize) serves it and the subspace solver; they differ only in their
// NewtonLinearSolve.
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "breast_tumour_registration/fem/inversion_check.h"
#include "breast_tumour_registration/fem/hessian_pattern.h"
#include "breast_tumour_registration/fem/total_energy.h"

namespace btr {

enum class StopReason {
  GradientTolerance,  ///< |g| <= abs_tol + rel_tol max(|g0|, force_scale)   (converged)
  StepTolerance,      ///< the full Newton step of a fresh factorization is below step_tolerance (converged:
                      ///< the minimum of the Newton model is that close; the gradient is at round-off)
  Stalled,            ///< damped line-search steps below step_tolerance while the full step is not (not converged)
  InvertedAfterStall, ///< a stall let the line search invert elements and the solve ended with too many
                      ///< inverted: the uninverted stall state is kept (not converged)
  MaxIterations,      ///< iteration cap reached (not converged)
  LineSearchFailed,   ///< no step decreased the energy even on a fresh factorization; state is the best found
  Aborted,            ///< the callback asked to stop
};
std::string to_string(StopReason r);

struct IterationInfo {
  int iteration = 0;
  double energy = 0;         ///< after the step [J]
  double gradient_norm = 0;  ///< free-DOF gradient 2-norm after the step [N]
  double alpha = 0;          ///< accepted step length
  double step_norm = 0;      ///< max vertex displacement of the accepted step [m]
  long inverted = 0;         ///< inverted tetrahedra after the step
  double elapsed = 0;        ///< seconds since the solve started
  double t_assembly = 0, t_factorization = 0, t_solve = 0, t_line_search = 0;  ///< this iteration [s]
  bool factorized = false;  ///< this iteration factorized (false: PCG on the lagged factor)
  int pcg_iterations = 0;
  bool inversion_limited = false;  ///< the inversion rule cut the step (LineSearchResult::inversion_limited)
};

struct NewtonOptions {
  int max_iterations = 100;
  double gradient_rel_tolerance = 1e-6;  ///< relative to max(initial gradient norm, force_scale)
  /// A physical force scale [N] (e.g. the body's weight) so that a warm start from a
  /// near-solution is judged against the problem's forces, not its own tiny residual.
  double force_scale = 0;
  double gradient_abs_tolerance = 1e-10; ///< [N]
  double step_tolerance = 1e-9;          ///< [m], on the full Newton step
  int max_line_search_steps = 40;
  double armijo = 1e-4;
  bool project_psd = true;
  /// With project_psd: once a full step was accepted and |g| is below 1% of the load, use the
  /// unprojected Hessian (full-space solver only), back to the projected one if it is not
  /// positive definite or its step makes no progress.
  bool exact_hessian_near_solution = true;
  /// Reuse the last Cholesky factor as a preconditioner for conjugate gradients on the
  /// new Hessian (inexact Newton); refactorize only when PCG does not reach the forcing
  /// tolerance within max_pcg_iterations. Off: a fresh factorization every iteration.
  bool reuse_factorization = true;
  int max_pcg_iterations = 25;
  /// Forcing term of the inexact Newton step: |H d + g| <= eta |g| with
  /// eta = min(max_forcing, sqrt(|g| / |g0|)) (superlinear convergence).
  double max_forcing = 0.1;
  /// Reject line-search steps that invert more tetrahedra than the current state has.
  bool forbid_new_inversions = true;
  /// When a stall lets the line search invert (recover_from_stall), the solve may end with at
  /// most this fraction of the tetrahedra newly inverted (a few elements passing a nearly flat
  /// state, reported); more means the mesh folded to meet its constraints, and the last
  /// uninverted state is kept (StopReason::InvertedAfterStall).
  double max_inverted_fraction_after_stall = 0.002;
  /// With inversions let in by a stall: once more than this fraction of the tetrahedra is
  /// newly inverted, the solve ends there as InvertedAfterStall (the guard's state restored)
  /// instead of folding on to the iteration cap. 0: never; the solve runs on and the count is
  /// judged at its end. ForwardGravity sets it (a folded gravity equilibrium is no equilibrium
  /// to keep, and its load continuation needs the failure early).
  double abandon_inverted_fraction = 0;
  /// A step that the inversion rule cut to this fraction of the Newton step or less is a stall
  /// of its own kind: the line search may invert from then on (as recover_from_stall does; the
  /// inversion guard above still applies). 0: only steps below step_tolerance are stalls. The
  /// surface step sets it (SurfaceStepOptions): soft tissue pulled by the skin springs otherwise
  /// crawls with ever shorter steps, far from equilibrium, and its skin looks settled.
  double inversion_stall_alpha = 0;
  /// Called after every accepted iteration; return false to abort.
  std::function<bool(const IterationInfo&)> callback;
};

struct NewtonResult {
  StopReason reason = StopReason::MaxIterations;
  bool converged = false;
  int iterations = 0;
  double initial_energy = 0, energy = 0;
  double initial_gradient_norm = 0, gradient_norm = 0;
  long inverted = 0;
  double seconds = 0;
  double t_assembly = 0, t_factorization = 0, t_solve = 0, t_line_search = 0;  ///< totals [s]
  int regularizations = 0;  ///< factorizations that needed a diagonal shift
  int factorizations = 0;    ///< numeric Cholesky factorizations
  int pcg_iterations = 0;    ///< total preconditioned CG iterations (lagged-factor steps)
  bool inversions_allowed = false;  ///< a stall made the line search accept new inversions
  std::vector<IterationInfo> history;
};

/// Outcome of trying a Newton direction.
/// TooSmall: the full (undamped) step is below step_tolerance; Stalled: the line search
/// accepted a step, but one below step_tolerance while the full step is not.
enum class StepOutcome { Taken, TooSmall, NoDecrease, Stalled };

/// After a direction that did not make progress (TooSmall, NoDecrease, Stalled), what a stall
/// calls for, in order: a direction from the lagged factor is retried on a fresh
/// factorization; then a line search that refused new inversions may invert elements (the
/// stable Neo-Hookean energy is defined there; opt.forbid_new_inversions is cleared and
/// res.inversions_allowed set). Returns true when the caller should retry (refactorizing);
/// otherwise sets the final reason in res (StepTolerance, converged; LineSearchFailed or
/// Stalled, not converged) and returns false.
bool recover_from_stall(StepOutcome outcome, bool direction_was_lagged, NewtonOptions& opt, NewtonResult& res);

/// The linear algebra of a Newton iteration: the one thing in which the full-space solver
/// (sparse Cholesky, CHOLMOD) and the subspace solver (x = x0 + U q, dense LDLT of U^T H U)
/// differ. The driver (newton_minimize) owns everything else: the stopping rules, the stall
/// recovery, the inversion guard, the line search and the switch to the exact Hessian.
/// Vectors are in the solve's coordinates (the free DOFs, or the subspace's), except where
/// the name says free.
class NewtonLinearSolve {
 public:
  virtual ~NewtonLinearSolve() = default;
  /// The gradient in the solve's coordinates, from the free-DOF gradient.
  virtual Eigen::VectorXd reduce(const Eigen::VectorXd& g_free) const = 0;
  /// The free-DOF displacement of a step d.
  virtual Eigen::VectorXd expand(const Eigen::VectorXd& d) const = 0;
  /// The Hessian of this iteration: the assembler's matrix minus the low-rank part.
  virtual void set_hessian(const HessianAssembler& H, const LowRankHessian& low) = 0;
  /// A factor of an earlier Hessian (same pattern) that can precondition conjugate gradients.
  virtual bool has_factor() const = 0;
  /// Conjugate gradients on this iteration's Hessian preconditioned by the lagged factor, to
  /// |H d - rhs| <= eta |rhs| within max_iterations; false when it did not get there.
  virtual bool lagged_solve(const Eigen::VectorXd& rhs, double eta, int max_iterations, Eigen::VectorXd& d,
                            int& iterations) = 0;
  /// Factorizes this iteration's Hessian. With may_shift false, returns false if it is not
  /// positive definite (the exact Hessian tried near the solution); with it, a growing diagonal
  /// shift is tried (counted in regularizations) and SolverError thrown if none helps.
  virtual bool factorize(bool may_shift, int& regularizations) = 0;
  /// Solves with the last factor (the low-rank part included).
  virtual Eigen::VectorXd solve(const Eigen::VectorXd& rhs) = 0;
  /// Whether the unprojected Hessian may be used near the solution.
  virtual bool supports_exact_hessian() const { return true; }
  /// Drops the numeric factor.
  virtual void forget_factor() = 0;
};

/// Newton's method with a PSD-projected Hessian and a backtracking line search (thesis Sec.
/// 3.2, Algorithm 1 in a subspace), the one driver of both solvers: minimizes `energy` over
/// the free vertices of x in place (fixed vertices keep their positions); `linear` solves for
/// the direction. Converged means the gradient criterion held (|g| <= abs_tol + rel_tol
/// max(|g0|, force_scale), in the solve's coordinates), or a fresh full Newton step fell below
/// step_tolerance; a damped step below it is a stall, never convergence. Throws SolverError if
/// the energy is not finite at the start or the Hessian cannot be factorized.
NewtonResult newton_minimize(const TotalEnergy& energy, HessianAssembler& H, const InversionCheck& inversions,
                             NewtonLinearSolve& linear, Points& x, const NewtonOptions& opt);

/// Newton solver bound to one sparsity pattern: the CHOLMOD symbolic analysis is done on
/// the first solve and reused by every later solve with the same assembler.
class NewtonSolver {
 public:
  /// `inversions` counts inverted elements for the line search and the fold allowances (linear
  /// tetrahedra convert to it; may be empty).
  NewtonSolver(std::shared_ptr<HessianAssembler> assembler, InversionCheck inversions);
  ~NewtonSolver();
  NewtonSolver(const NewtonSolver&) = delete;
  NewtonSolver& operator=(const NewtonSolver&) = delete;

  /// newton_minimize with this solver's sparse Cholesky factorization.
  NewtonResult solve(const TotalEnergy& energy, Points& x, const NewtonOptions& opt);

  HessianAssembler& assembler() { return *assembler_; }

  /// Drops the numeric factor (the symbolic analysis stays): the next solve starts as a new
  /// solver would, without a lagged factor of an earlier problem as its preconditioner.
  void forget_factor();

 private:
  struct Impl;
  std::shared_ptr<HessianAssembler> assembler_;
  InversionCheck inversions_;
  std::unique_ptr<Impl> impl_;
};

}  // namespace btr
