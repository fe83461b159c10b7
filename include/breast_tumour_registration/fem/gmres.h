// GMRES for a square, possibly non-symmetric system given only as products (Saad and Schultz
// 1986), right-preconditioned so that the residual it minimises is the true one: it solves
// A M^-1 y = b and returns x = M^-1 y. Arnoldi with modified Gram-Schmidt, the least-squares
// problem kept triangular by Givens rotations; no restart (the Krylov basis is kept whole, so
// max_it bounds the memory: max_it + 1 vectors). Used where an operator is known only through
// finite differences (the rest shape's response to the material, tumour_uncertainty.cpp).
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <vector>

namespace btr {

struct GmresResult {
  bool converged = false;    ///< |b - A x| <= rel_tol |b| held
  int iterations = 0;        ///< products with A
  double relative_residual = 0;  ///< |b - A x| / |b| as the Givens recursion gives it
};

/// apply_A(v) returns A v; apply_Minv(v) returns M^-1 v. x starts at zero.
template <class ApplyA, class ApplyMinv>
GmresResult gmres(ApplyA&& apply_A, ApplyMinv&& apply_Minv, const Eigen::VectorXd& b, double rel_tol, int max_it,
                  Eigen::VectorXd& x) {
  GmresResult out;
  x = Eigen::VectorXd::Zero(b.size());
  const double beta = b.norm();
  if (!(beta > 0)) {
    out.converged = std::isfinite(beta);
    return out;
  }
  std::vector<Eigen::VectorXd> V;  // orthonormal Krylov basis
  V.reserve(static_cast<size_t>(max_it) + 1);
  V.push_back(b / beta);
  Eigen::MatrixXd R = Eigen::MatrixXd::Zero(max_it + 1, max_it);  // rotated Hessenberg matrix
  Eigen::VectorXd cs = Eigen::VectorXd::Zero(max_it), sn = Eigen::VectorXd::Zero(max_it);
  Eigen::VectorXd g = Eigen::VectorXd::Zero(max_it + 1);  // rotated right-hand side
  g(0) = beta;
  int k = 0;
  double residual = beta;
  for (; k < max_it && residual > rel_tol * beta; ++k) {
    Eigen::VectorXd w = apply_A(apply_Minv(V[k]));
    ++out.iterations;
    for (int i = 0; i <= k; ++i) {
      R(i, k) = w.dot(V[i]);
      w -= R(i, k) * V[i];
    }
    const double h = w.norm();
    R(k + 1, k) = h;
    for (int i = 0; i < k; ++i) {  // earlier rotations on the new column
      const double a = R(i, k), c = R(i + 1, k);
      R(i, k) = cs(i) * a + sn(i) * c;
      R(i + 1, k) = -sn(i) * a + cs(i) * c;
    }
    const double d = std::hypot(R(k, k), R(k + 1, k));
    if (!(d > 0) || !std::isfinite(d)) break;  // breakdown: A M^-1 singular on the basis
    cs(k) = R(k, k) / d;
    sn(k) = R(k + 1, k) / d;
    R(k, k) = d;
    R(k + 1, k) = 0;
    g(k + 1) = -sn(k) * g(k);
    g(k) = cs(k) * g(k);
    residual = std::abs(g(k + 1));
    if (!(h > 1e-14 * beta)) {  // happy breakdown: the solution lies in the basis
      ++k;
      break;
    }
    V.push_back(w / h);
  }
  if (k > 0) {
    const Eigen::VectorXd y = R.topLeftCorner(k, k).triangularView<Eigen::Upper>().solve(g.head(k));
    Eigen::VectorXd z = Eigen::VectorXd::Zero(b.size());
    for (int i = 0; i < k; ++i) z += y(i) * V[i];
    x = apply_Minv(z);
  }
  out.relative_residual = residual / beta;
  out.converged = residual <= rel_tol * beta && x.allFinite();
  return out;
}

}  // namespace btr
