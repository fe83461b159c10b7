#include "breast_tumour_registration/geometry/self_intersection.h"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/Surface_mesh.h>

#include <iterator>
#include <utility>
#include <vector>

#include "breast_tumour_registration/base/errors.h"

namespace btr {

long self_intersecting_face_pairs(const SurfaceMesh& s) {
  using K = CGAL::Exact_predicates_inexact_constructions_kernel;
  using Mesh = CGAL::Surface_mesh<K::Point_3>;
  Mesh mesh;
  std::vector<Mesh::Vertex_index> v;
  v.reserve(static_cast<size_t>(s.V.rows()));
  for (Eigen::Index i = 0; i < s.V.rows(); ++i) v.push_back(mesh.add_vertex(K::Point_3(s.V(i, 0), s.V(i, 1), s.V(i, 2))));
  for (Eigen::Index f = 0; f < s.F.rows(); ++f) {
    for (int k = 0; k < 3; ++k)
      if (s.F(f, k) < 0 || s.F(f, k) >= s.V.rows()) throw InputError("self_intersecting_face_pairs: face index out of range");
    if (mesh.add_face(v[s.F(f, 0)], v[s.F(f, 1)], v[s.F(f, 2)]) == Mesh::null_face())
      throw InputError("self_intersecting_face_pairs: face " + std::to_string(f) + " makes the surface non-manifold");
  }
  std::vector<std::pair<Mesh::Face_index, Mesh::Face_index>> pairs;
  CGAL::Polygon_mesh_processing::self_intersections(mesh, std::back_inserter(pairs));
  return static_cast<long>(pairs.size());
}

}  // namespace btr
