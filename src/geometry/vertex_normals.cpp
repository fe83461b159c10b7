#include "breast_tumour_registration/geometry/vertex_normals.h"

namespace btr {

Points vertex_normals(const SurfaceMesh& s) {
  Points n = Points::Zero(s.V.rows(), 3);
  for (Eigen::Index f = 0; f < s.F.rows(); ++f) {
    const Vec3 a = s.V.row(s.F(f, 0)), b = s.V.row(s.F(f, 1)), c = s.V.row(s.F(f, 2));
    const Vec3 w = (b - a).cross(c - a);  // twice the area, along the face normal
    for (int k = 0; k < 3; ++k) n.row(s.F(f, k)) += w.transpose();
  }
  for (Eigen::Index v = 0; v < n.rows(); ++v) {
    const double len = n.row(v).norm();
    if (len > 0) n.row(v) /= len;
  }
  return n;
}

void displace_along_normals(SurfaceMesh& s, double sd, const std::function<double()>& standard_normal) {
  const Points n = vertex_normals(s);
  for (Eigen::Index v = 0; v < s.V.rows(); ++v) s.V.row(v) += sd * standard_normal() * n.row(v);
}

}  // namespace btr
