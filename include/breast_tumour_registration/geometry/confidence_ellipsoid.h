// The 95 % region of a point with a Gaussian distribution (a registered tumour centroid with
// its covariance), as an ellipsoid: what the cross-section PNG and the RViz marker draw.
#pragma once

#include "breast_tumour_registration/base/types.h"

namespace btr {

/// `axes`: a rotation whose columns are the covariance's eigenvectors (eigenvalues ascending);
/// semi-axes sqrt(chi2_3(0.95) lambda_i) [m], chi2_3(0.95) = 7.8147.
struct Ellipsoid95 {
  Mat3 axes = Mat3::Identity();
  Vec3 semi_axes = Vec3::Zero();
};
Ellipsoid95 ellipsoid_95(const Mat3& covariance);

}  // namespace btr
