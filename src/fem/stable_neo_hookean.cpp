#include "breast_tumour_registration/fem/stable_neo_hookean.h"

#include <Eigen/SVD>
#include <array>
#include <cmath>
#include <string>

#include "breast_tumour_registration/base/errors.h"
#include "breast_tumour_registration/fem/small_matrices.h"

namespace btr {
namespace {

Vec9 cofactor_vec(const Mat3& F) { return determinant_gradient(F); }

Eigen::Map<const Vec9> vec(const Mat3& M) { return Eigen::Map<const Vec9>(M.data()); }

// Eigen-decomposition of the SNH Hessian in the SVD frame: 9 eigenvalues and the
// 3x3 SVD-frame matrices D_k whose U D_k V^T are the (orthonormal) eigenmatrices.
void decompose(double mu, double lambda, const Mat3& F, Mat3& U, Mat3& V, Vec9& eval,
               std::array<Mat3, 9>& D) {
  Vec3 S;
  rotation_variant_svd(F, U, S, V);
  const double J = S.prod();
  const double kappa = lambda * (J - 1.0) - mu;  // d psi / dJ
  const double s2 = 1.0 / std::sqrt(2.0);
  // Twist (antisymmetric) and flip (symmetric off-diagonal) pairs (j,k), third index i.
  const int pairs[3][3] = {{1, 2, 0}, {0, 2, 1}, {0, 1, 2}};
  for (int p = 0; p < 3; ++p) {
    const int j = pairs[p][0], k = pairs[p][1], i = pairs[p][2];
    Mat3 T = Mat3::Zero(), L = Mat3::Zero();
    T(j, k) = s2; T(k, j) = -s2;
    L(j, k) = s2; L(k, j) = s2;
    D[p] = T;
    eval[p] = mu + kappa * S[i];
    D[3 + p] = L;
    eval[3 + p] = mu - kappa * S[i];
  }
  // Scaling block: mu I + lambda g g^T + kappa d^2J/dS^2 restricted to diagonal perturbations.
  const Vec3 g(S[1] * S[2], S[0] * S[2], S[0] * S[1]);
  Mat3 A = mu * Mat3::Identity() + lambda * g * g.transpose();
  Mat3 HJ;
  HJ << 0, S[2], S[1], S[2], 0, S[0], S[1], S[0], 0;
  A += kappa * HJ;
  Eigen::SelfAdjointEigenSolver<Mat3> es(A);
  for (int s = 0; s < 3; ++s) {
    eval[6 + s] = es.eigenvalues()[s];
    D[6 + s] = es.eigenvectors().col(s).asDiagonal();
  }
}

}  // namespace

void rotation_variant_svd(const Mat3& F, Mat3& U, Vec3& S, Mat3& V) {
  Eigen::JacobiSVD<Mat3> svd(F, Eigen::ComputeFullU | Eigen::ComputeFullV);
  U = svd.matrixU();
  V = svd.matrixV();
  S = svd.singularValues();
  if (U.determinant() < 0) {
    U.col(2) *= -1;
    S[2] *= -1;
  }
  if (V.determinant() < 0) {
    V.col(2) *= -1;
    S[2] *= -1;
  }
}

LameParameters lame_from_young_poisson(double E, double nu) {
  if (!std::isfinite(E) || E <= 0)
    throw InputError("Young's modulus must be a positive number of pascals, got " + std::to_string(E));
  if (!std::isfinite(nu) || nu < 0.0 || nu >= 0.5)
    throw InputError("Poisson's ratio must be in [0, 0.5), got " + std::to_string(nu) +
                     " (use 0.499 for nearly incompressible tissue)");
  return {E / (2.0 * (1.0 + nu)), E * nu / ((1.0 + nu) * (1.0 - 2.0 * nu))};
}

StableNeoHookean::StableNeoHookean(double E, double nu) {
  const LameParameters l = lame_from_young_poisson(E, nu);
  mu_ = l.mu;
  lambda_ = l.lambda + l.mu;
}

double StableNeoHookean::youngs_modulus() const {
  const double lambda_lame = lambda_ - mu_;
  return mu_ * (3 * lambda_lame + 2 * mu_) / (lambda_lame + mu_);
}

StableNeoHookean StableNeoHookean::from_lame(double mu, double lambda_lame) {
  if (!(mu > 0) || !(lambda_lame >= 0) || !std::isfinite(mu) || !std::isfinite(lambda_lame))
    throw InputError("Lame parameters must satisfy mu > 0 and lambda >= 0");
  StableNeoHookean m;
  m.mu_ = mu;
  m.lambda_ = lambda_lame + mu;
  return m;
}

double StableNeoHookean::psi(const Mat3& F) const {
  const double Ic = F.squaredNorm();
  const double Jm1 = F.determinant() - 1.0;
  return 0.5 * mu_ * (Ic - 3.0) - mu_ * Jm1 + 0.5 * lambda_ * Jm1 * Jm1;
}

Mat3 StableNeoHookean::pk1(const Mat3& F) const {
  const double J = F.determinant();
  Mat3 dJ;
  dJ.col(0) = F.col(1).cross(F.col(2));
  dJ.col(1) = F.col(2).cross(F.col(0));
  dJ.col(2) = F.col(0).cross(F.col(1));
  return mu_ * F + (lambda_ * (J - 1.0) - mu_) * dJ;
}

Mat9 StableNeoHookean::hessian(const Mat3& F) const {
  const double J = F.determinant();
  const Vec9 g = cofactor_vec(F);
  const Mat9 HJ = determinant_hessian(F);
  return mu_ * Mat9::Identity() + lambda_ * g * g.transpose() + (lambda_ * (J - 1.0) - mu_) * HJ;
}

Mat9 StableNeoHookean::clamped_hessian(const Mat3& F) const {
  Mat3 U, V;
  Vec9 eval;
  std::array<Mat3, 9> D;
  decompose(mu_, lambda_, F, U, V, eval, D);
  // H+ = H - sum over negative eigenpairs of lambda_k q_k q_k^T: near rest most elements
  // have no negative eigenvalue, so this is much cheaper than summing nine outer products.
  Mat9 H = hessian(F);
  for (int k = 0; k < 9; ++k) {
    if (eval[k] >= 0) continue;
    const Mat3 Q = U * D[k] * V.transpose();
    H.noalias() -= eval[k] * vec(Q) * vec(Q).transpose();
  }
  return H;
}

Vec9 StableNeoHookean::analytic_eigenvalues(const Mat3& F) const {
  Mat3 U, V;
  Vec9 eval;
  std::array<Mat3, 9> D;
  decompose(mu_, lambda_, F, U, V, eval, D);
  return eval;
}

}  // namespace btr
