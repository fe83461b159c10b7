#include "breast_tumour_registration/geometry/surface_orientation.h"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/orient_polygon_soup.h>

#include <array>
#include <string>
#include <vector>

#include "breast_tumour_registration/base/errors.h"
#include "breast_tumour_registration/geometry/metrics.h"

namespace btr {

long orient_closed_surface(SurfaceMesh& s, const std::string& name) {
  using K = CGAL::Exact_predicates_inexact_constructions_kernel;
  std::vector<K::Point_3> points;
  points.reserve(static_cast<size_t>(s.V.rows()));
  for (Eigen::Index i = 0; i < s.V.rows(); ++i) points.emplace_back(s.V(i, 0), s.V(i, 1), s.V(i, 2));
  std::vector<std::array<std::size_t, 3>> faces(static_cast<size_t>(s.F.rows()));
  for (Eigen::Index f = 0; f < s.F.rows(); ++f)
    for (int k = 0; k < 3; ++k) faces[static_cast<size_t>(f)][k] = static_cast<std::size_t>(s.F(f, k));
  const bool manifold = CGAL::Polygon_mesh_processing::orient_polygon_soup(points, faces);
  if (!manifold || static_cast<Eigen::Index>(points.size()) != s.V.rows())
    throw InputError(name + ": the faces cannot be oriented consistently without splitting vertices "
                            "(non-manifold or non-orientable surface); repair it in a mesh editor");
  Triangles F(s.F.rows(), 3);
  for (Eigen::Index f = 0; f < s.F.rows(); ++f)
    for (int k = 0; k < 3; ++k) F(f, k) = static_cast<int>(faces[static_cast<size_t>(f)][k]);
  if (enclosed_volume(SurfaceMesh{s.V, F}) < 0) F.col(1).swap(F.col(2));
  // A face is flipped when its vertex cycle runs the other way (the soup may rotate it).
  long flipped = 0;
  for (Eigen::Index f = 0; f < s.F.rows(); ++f) {
    const int a = s.F(f, 0), b = s.F(f, 1);
    bool same = false;
    for (int k = 0; k < 3; ++k) same = same || (F(f, k) == a && F(f, (k + 1) % 3) == b);
    flipped += same ? 0 : 1;
  }
  s.F = F;
  return flipped;
}

}  // namespace btr
