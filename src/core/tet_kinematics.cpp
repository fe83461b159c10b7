#include "breast_tumour_registration/core/tet_kinematics.h"

#include <string>

#include "breast_tumour_registration/core/errors.h"

namespace btr {

std::vector<TetRestData> compute_rest_data(const TetMesh& rest) {
  std::vector<TetRestData> out(rest.T.rows());
  for (Eigen::Index t = 0; t < rest.T.rows(); ++t) {
    const Eigen::Vector4i tet = rest.T.row(t);
    Mat3 Dm;
    const Vec3 X0 = rest.V.row(tet[0]);
    for (int c = 0; c < 3; ++c) Dm.col(c) = rest.V.row(tet[c + 1]).transpose() - X0;
    const double det = Dm.determinant();
    if (!(det > 0) || !std::isfinite(det))
      throw InputError("rest tetrahedron " + std::to_string(t) + " is " + (det < 0 ? "inverted" : "degenerate") +
                       " (volume " + std::to_string(det / 6.0) + " m^3)");
    out[t].Dm_inv = Dm.inverse();
    out[t].volume = det / 6.0;
  }
  return out;
}

Mat9x12 deformation_gradient_jacobian(const Mat3& Dm_inv) {
  // F_ij = sum_k (x_{k+1,i} - x_{0,i}) Dm_inv(k,j); vec index of F_ij is 3j + i.
  Mat9x12 B = Mat9x12::Zero();
  for (int j = 0; j < 3; ++j) {
    const double s = Dm_inv(0, j) + Dm_inv(1, j) + Dm_inv(2, j);
    for (int i = 0; i < 3; ++i) {
      B(3 * j + i, i) = -s;
      for (int k = 0; k < 3; ++k) B(3 * j + i, 3 * (k + 1) + i) = Dm_inv(k, j);
    }
  }
  return B;
}

long count_inverted(const Points& x, const Tetrahedra& T) {
  long n = 0;
#pragma omp parallel for reduction(+ : n) schedule(static)
  for (Eigen::Index t = 0; t < T.rows(); ++t) {
    const Vec3 a = x.row(T(t, 0));
    const double v = (x.row(T(t, 1)).transpose() - a).dot((x.row(T(t, 2)).transpose() - a).cross(x.row(T(t, 3)).transpose() - a));
    if (!(v > 0)) ++n;
  }
  return n;
}

Eigen::VectorXd lumped_masses(const TetMesh& rest, double density) {
  if (!(density > 0) || !std::isfinite(density))
    throw InputError("density must be positive (kg/m^3), got " + std::to_string(density));
  Eigen::VectorXd m = Eigen::VectorXd::Zero(rest.V.rows());
  for (Eigen::Index t = 0; t < rest.T.rows(); ++t) {
    const Vec3 a = rest.V.row(rest.T(t, 0));
    const double v = std::abs((rest.V.row(rest.T(t, 1)).transpose() - a)
                                  .dot((rest.V.row(rest.T(t, 2)).transpose() - a).cross(rest.V.row(rest.T(t, 3)).transpose() - a))) / 6.0;
    for (int c = 0; c < 4; ++c) m[rest.T(t, c)] += density * v / 4.0;
  }
  return m;
}

}  // namespace btr
