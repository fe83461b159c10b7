#include "breast_tumour_registration/fem/tet_kinematics.h"

#include <string>

#include "breast_tumour_registration/base/errors.h"

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

Vec12 tet_gradient_from_stress(const Mat3& P, const Mat3& Dm_inv, double volume) {
  const Mat3 G = volume * P * Dm_inv.transpose();
  Vec12 g;
  g.segment<3>(3) = G.col(0);
  g.segment<3>(6) = G.col(1);
  g.segment<3>(9) = G.col(2);
  g.segment<3>(0) = -(G.col(0) + G.col(1) + G.col(2));
  return g;
}

Mat12 tet_hessian_from_stress_hessian(const Mat9& H9, const Mat3& Dinv, double volume) {
  // dF/dx = G^T (x) I3 with G (4x3) the shape-function gradients, so block (a,b) of
  // B^T H B is sum_jl G(a,j) G(b,l) H_jl (3x3 blocks of H9).
  Eigen::Matrix<double, 4, 3> G;
  G.bottomRows<3>() = Dinv;
  G.row(0) = -Dinv.colwise().sum();
  Eigen::Matrix<double, 9, 12> HG;  // HG.block(3j, 3b) = sum_l G(b,l) H_jl
  for (int b = 0; b < 4; ++b)
    HG.middleCols<3>(3 * b) = G(b, 0) * H9.middleCols<3>(0) + G(b, 1) * H9.middleCols<3>(3) + G(b, 2) * H9.middleCols<3>(6);
  Mat12 K;
  for (int a = 0; a < 4; ++a)
    K.middleRows<3>(3 * a) = G(a, 0) * HG.middleRows<3>(0) + G(a, 1) * HG.middleRows<3>(3) + G(a, 2) * HG.middleRows<3>(6);
  return volume * K;
}

bool is_inverted(const Points& x, const Tetrahedra& T, Eigen::Index t) {
  const Vec3 a = x.row(T(t, 0));
  const double v = (x.row(T(t, 1)).transpose() - a).dot((x.row(T(t, 2)).transpose() - a).cross(x.row(T(t, 3)).transpose() - a));
  return !(v > 0);
}

long count_inverted(const Points& x, const Tetrahedra& T) {
  long n = 0;
#pragma omp parallel for reduction(+ : n) schedule(static)
  for (Eigen::Index t = 0; t < T.rows(); ++t)
    if (is_inverted(x, T, t)) ++n;
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
