// Preconditioned conjugate gradients for a symmetric positive definite system, started from
// the preconditioned right-hand side (with a lagged Cholesky factor as preconditioner this
// start is the lagged Newton step). Shared by the full-space and subspace Newton solvers.
#pragma once

#include <Eigen/Core>

namespace btr {

/// apply_A(v) returns A v; apply_Minv(v) returns M^-1 v. Stops when |b - A x| <= rel_tol |b|
/// (true) or after max_it iterations or on a non-positive curvature (false).
template <class ApplyA, class ApplyMinv>
bool preconditioned_cg(ApplyA&& apply_A, ApplyMinv&& apply_Minv, const Eigen::VectorXd& b, double rel_tol, int max_it,
                       Eigen::VectorXd& x, int& iterations) {
  x = apply_Minv(b);
  Eigen::VectorXd r = b - apply_A(x);
  const double stop = rel_tol * b.norm();
  iterations = 0;
  if (r.norm() <= stop) return x.allFinite();
  Eigen::VectorXd z = apply_Minv(r), p = z;
  double rz = r.dot(z);
  for (iterations = 1; iterations <= max_it; ++iterations) {
    const Eigen::VectorXd Ap = apply_A(p);
    const double pAp = p.dot(Ap);
    if (!(pAp > 0)) return false;
    const double a = rz / pAp;
    x += a * p;
    r -= a * Ap;
    if (r.norm() <= stop) return x.allFinite();
    z = apply_Minv(r);
    const double rz_new = r.dot(z);
    p = z + (rz_new / rz) * p;
    rz = rz_new;
  }
  return false;
}

}  // namespace btr
