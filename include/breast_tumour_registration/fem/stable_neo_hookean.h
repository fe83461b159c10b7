// Stable Neo-Hookean material (Smith, de Goes, Kim 2018, "Stable Neo-Hookean Flesh
// Simulation"), in the log-free form used by HOBAK and the Dynamic Deformables course:
//
//   psi(F) = mu/2 (I_C - 3) - mu (J - 1) + lambda/2 (J - 1)^2,   I_C = |F|^2, J = det F
//
// (thesis eq. 3.5 writes the same energy with invariants). It is defined and smooth
// for inverted elements (J <= 0), and psi(I) = 0, P(I) = 0.
//
// Lame parameters: linearising psi around F = I gives linear elasticity with shear
// modulus mu and first Lame parameter lambda - mu, so following the paper's Sec. 3.4
// (match linear elasticity) we set mu = mu_L and lambda = lambda_L + mu_L. This keeps
// nu = 0 (lambda_L = 0) well defined, which the (J - alpha) form with alpha = 1 + mu/lambda
// would not be.
//
// Derivatives are with respect to vec(F), column-major (F = [f0 f1 f2], vec = [f0; f1; f2]).
#pragma once

#include "breast_tumour_registration/base/types.h"

namespace btr {

/// Classical Lame parameters from Young's modulus E [Pa] and Poisson's ratio nu.
/// Throws InputError unless E > 0 and 0 <= nu < 0.5 (finite).
struct LameParameters {
  double mu;
  double lambda;
};
LameParameters lame_from_young_poisson(double youngs_modulus, double poisson_ratio);

class StableNeoHookean {
 public:
  /// From Young's modulus [Pa] and Poisson's ratio (see lame_from_young_poisson).
  StableNeoHookean(double youngs_modulus, double poisson_ratio);
  /// From the classical Lame parameters (mu > 0, lambda >= 0).
  static StableNeoHookean from_lame(double mu, double lambda_lame);

  /// The same material without its volume term lambda/2 (J - 1)^2: psi = mu/2 (I_C - 3) - mu (J - 1).
  /// With NodalVolumeEnergy carrying the volume term on nodal averages (near-incompressible tissue).
  StableNeoHookean shear_part() const {
    StableNeoHookean m = *this;
    m.lambda_ = 0;
    return m;
  }

  double mu() const { return mu_; }          ///< shear modulus [Pa]
  double lambda() const { return lambda_; }  ///< SNH volume stiffness lambda_L + mu [Pa]
  /// Young's modulus [Pa] of the small-strain limit: mu (3 lambda_L + 2 mu) / (lambda_L + mu).
  double youngs_modulus() const;

  /// Energy density psi(F) [J/m^3].
  double psi(const Mat3& F) const;
  /// First Piola-Kirchhoff stress P = d psi / dF [Pa].
  Mat3 pk1(const Mat3& F) const;
  /// d^2 psi / d vec(F)^2: mu I + lambda g g^T + (lambda (J-1) - mu) H_J, with g = vec(cof F).
  Mat9 hessian(const Mat3& F) const;
  /// Analytic positive semi-definite projection of hessian(F): twist, flip and scaling
  /// eigenpairs from the rotation-variant SVD (Smith et al. 2018, Sec. 4.6 / Kim &
  /// Eberle 2020, Ch. 7), negative eigenvalues clamped to zero.
  Mat9 clamped_hessian(const Mat3& F) const;

  /// Eigenvalues of hessian(F) from the analytic decomposition (for tests and diagnostics).
  Vec9 analytic_eigenvalues(const Mat3& F) const;

 private:
  StableNeoHookean() = default;
  double mu_ = 0;
  double lambda_ = 0;
};

/// Rotation-variant SVD: F = U diag(S) V^T with U, V proper rotations; the sign of an
/// inversion is carried by the last singular value.
void rotation_variant_svd(const Mat3& F, Mat3& U, Vec3& S, Mat3& V);

}  // namespace btr
