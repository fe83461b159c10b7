#include "breast_tumour_registration/fem/determinant_eigensystem.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>

#include "breast_tumour_registration/fem/stable_neo_hookean.h"

namespace btr {

Mat9 projected_determinant_hessian(const Mat3& F, double scale, double shift) {
  Mat9 H = Mat9::Zero();
  if (scale == 0) return Mat9::Identity() * std::max(shift, 0.0);
  Mat3 U, V;
  Vec3 S;
  rotation_variant_svd(F, U, S, V);
  // The sum of the positive eigenpairs (without a shift at most five of the nine: the scaling
  // block has trace 0).
  auto add = [&](double lambda, const Mat3& D) {
    lambda += shift;
    if (!(lambda > 0)) return;
    const Mat3 Q = U * D * V.transpose();
    const Eigen::Map<const Vec9> q(Q.data());
    H.noalias() += lambda * q * q.transpose();
  };
  const double s2 = 1.0 / std::sqrt(2.0);
  const int pairs[3][3] = {{1, 2, 0}, {0, 2, 1}, {0, 1, 2}};
  for (const auto& p : pairs) {
    const int j = p[0], k = p[1], i = p[2];
    Mat3 twist = Mat3::Zero(), flip = Mat3::Zero();
    twist(j, k) = s2;
    twist(k, j) = -s2;
    flip(j, k) = s2;
    flip(k, j) = s2;
    add(scale * S[i], twist);
    add(-scale * S[i], flip);
  }
  Mat3 A;
  A << 0, S[2], S[1], S[2], 0, S[0], S[1], S[0], 0;
  Eigen::SelfAdjointEigenSolver<Mat3> es(scale * A);
  for (int s = 0; s < 3; ++s) add(es.eigenvalues()[s], es.eigenvectors().col(s).asDiagonal());
  return H;
}

}  // namespace btr
