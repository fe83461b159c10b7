#include "breast_tumour_registration/geometry/confidence_ellipsoid.h"

#include <Eigen/Eigenvalues>

namespace btr {

Ellipsoid95 ellipsoid_95(const Mat3& covariance) {
  const Eigen::SelfAdjointEigenSolver<Mat3> eig(0.5 * (covariance + covariance.transpose()));
  constexpr double kChi2_3_95 = 7.8147;  // the 95 % quantile of chi-squared with 3 degrees of freedom
  Ellipsoid95 e;
  e.axes = eig.eigenvectors();
  if (e.axes.determinant() < 0) e.axes.col(2) *= -1;  // a rotation
  e.semi_axes = (kChi2_3_95 * eig.eigenvalues().cwiseMax(0.0)).cwiseSqrt();
  return e;
}

}  // namespace btr
