// Small dense helpers shared by the energy kernels.
#pragma once

#include <Eigen/Eigenvalues>
#include <algorithm>

#include "breast_tumour_registration/core/types.h"

namespace btr {

/// [v]x: the matrix with [v]x w = v x w.
inline Mat3 cross_matrix(const Vec3& v) {
  Mat3 m;
  m << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  return m;
}

/// Pseudo-inverse of a symmetric positive semi-definite 6x6 matrix: eigenvalues below 1e-12 of
/// the largest count as zero (landmarks on a line, or a rotationally symmetric surface, leave a
/// rotation of the pose undetermined). A negative eigenvalue above that floor is inverted as is.
inline Mat6 symmetric_pseudo_inverse(const Mat6& F) {
  const Eigen::SelfAdjointEigenSolver<Mat6> es(F);
  const double floor = 1e-12 * std::max(es.eigenvalues().cwiseAbs().maxCoeff(), 1e-300);
  Vec6 inv = Vec6::Zero();
  for (int k = 0; k < 6; ++k)
    if (std::abs(es.eigenvalues()[k]) > floor) inv[k] = 1.0 / es.eigenvalues()[k];
  return es.eigenvectors() * inv.asDiagonal() * es.eigenvectors().transpose();
}

}  // namespace btr
