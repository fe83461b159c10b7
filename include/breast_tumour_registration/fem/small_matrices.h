// Small dense helpers shared by the energy kernels.
#pragma once

#include <Eigen/Eigenvalues>
#include <algorithm>

#include "breast_tumour_registration/base/types.h"

namespace btr {

/// [v]x: the matrix with [v]x w = v x w.
inline Mat3 cross_matrix(const Vec3& v) {
  Mat3 m;
  m << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  return m;
}

/// dJ/dvec(F) = vec(cof F) for J = det F (vec column-major).
inline Vec9 determinant_gradient(const Mat3& F) {
  Vec9 g;
  g.segment<3>(0) = F.col(1).cross(F.col(2));
  g.segment<3>(3) = F.col(2).cross(F.col(0));
  g.segment<3>(6) = F.col(0).cross(F.col(1));
  return g;
}

/// d2J/dvec(F)2 for J = det F: antisymmetric cross-product blocks (Kim & Eberle 2020, Sec. 4.2).
inline Mat9 determinant_hessian(const Mat3& F) {
  Mat9 HJ = Mat9::Zero();
  const Mat3 f0 = cross_matrix(F.col(0)), f1 = cross_matrix(F.col(1)), f2 = cross_matrix(F.col(2));
  HJ.block<3, 3>(0, 3) = -f2;
  HJ.block<3, 3>(0, 6) = f1;
  HJ.block<3, 3>(3, 0) = f2;
  HJ.block<3, 3>(3, 6) = -f0;
  HJ.block<3, 3>(6, 0) = -f1;
  HJ.block<3, 3>(6, 3) = f0;
  return HJ;
}

/// A symmetric 9x9 matrix with its negative eigenvalues clamped to zero (numerical eigen-clamp).
inline Mat9 clamp_to_psd(const Mat9& H) {
  const Eigen::SelfAdjointEigenSolver<Mat9> es(H);
  return es.eigenvectors() * es.eigenvalues().cwiseMax(0.0).asDiagonal() * es.eigenvectors().transpose();
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
