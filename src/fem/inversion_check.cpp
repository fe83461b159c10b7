#include "breast_tumour_registration/fem/inversion_check.h"

#include <utility>

#include "breast_tumour_registration/fem/tet_kinematics.h"

namespace btr {

InversionCheck::InversionCheck(Tetrahedra T) : linear_(std::move(T)) {}

InversionCheck InversionCheck::quadratic(const QuadraticTetMesh& q, int quadrature_degree) {
  InversionCheck c;
  c.quadratic_ = q.T;
  std::vector<Vec4> points;
  for (const auto& p : tet_quadrature(quadrature_degree)) points.push_back(p.barycentric);
  for (int a = 0; a < 4; ++a) points.push_back(Vec4::Unit(a));
  for (const auto& e : kQuadraticTetEdges) {
    Vec4 b = Vec4::Zero();
    b[e[0]] = b[e[1]] = 0.5;
    points.push_back(b);
  }
  // Local coordinates xi_k = b_k (k = 1..3), b_0 = 1 - xi_1 - xi_2 - xi_3: d/dxi_k = d/db_k - d/db_0.
  for (const Vec4& b : points) {
    const Eigen::Matrix<double, 10, 4> Db = quadratic_shape_barycentric_derivatives(b);
    Eigen::Matrix<double, 10, 3> D;
    for (int k = 0; k < 3; ++k) D.col(k) = Db.col(k + 1) - Db.col(0);
    c.derivatives_.push_back(D);
  }
  return c;
}

long InversionCheck::count(const Points& x) const {
  if (linear_.rows()) return count_inverted(x, linear_);
  long n = 0;
#pragma omp parallel for reduction(+ : n) schedule(static)
  for (Eigen::Index t = 0; t < quadratic_.rows(); ++t) {
    Eigen::Matrix<double, 10, 3> X;
    for (int a = 0; a < 10; ++a) X.row(a) = x.row(quadratic_(t, a));
    for (const auto& D : derivatives_) {
      const Mat3 J = X.transpose() * D;  // column k: d position / d xi_k
      if (J.determinant() <= 0) {
        ++n;
        break;
      }
    }
  }
  return n;
}

}  // namespace btr
