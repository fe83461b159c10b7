#include "breast_tumour_registration/geometry/surface_attachment.h"

#include <algorithm>
#include <set>
#include <utility>

#include "breast_tumour_registration/base/errors.h"
#include "breast_tumour_registration/geometry/closest_point.h"
#include "breast_tumour_registration/geometry/validation.h"

namespace btr {

BoundaryAttachment attach_to_boundary(const TetMesh& mesh, const Points& P) {
  const Triangles F = boundary_faces(mesh);
  const SurfaceClosestPoint cp(mesh.V, F);
  BoundaryAttachment out;
  out.anchors.resize(P.rows());
  out.distances.resize(P.rows());
  for (Eigen::Index i = 0; i < P.rows(); ++i) {
    const ClosestPoint c = cp.query(P.row(i).transpose());
    Anchor& a = out.anchors[i];
    a.count = 3;
    for (int k = 0; k < 3; ++k) {
      a.v[k] = F(c.face, k);
      a.w[k] = c.barycentric[k];
    }
    out.distances[i] = c.distance;
    out.max_distance = std::max(out.max_distance, c.distance);
  }
  return out;
}

std::vector<int> boundary_vertices(const TetMesh& mesh) {
  const Triangles F = boundary_faces(mesh);
  std::vector<int> v(F.data(), F.data() + F.size());
  std::sort(v.begin(), v.end());
  v.erase(std::unique(v.begin(), v.end()), v.end());
  return v;
}

SurfaceMesh boundary_surface(const TetMesh& mesh, std::vector<int>* to_tet, std::vector<int>* from_tet) {
  const Triangles F = boundary_faces(mesh);
  const std::vector<int> verts = boundary_vertices(mesh);
  std::vector<int> compact(mesh.V.rows(), -1);
  SurfaceMesh s;
  s.V.resize(verts.size(), 3);
  for (size_t i = 0; i < verts.size(); ++i) {
    compact[verts[i]] = static_cast<int>(i);
    s.V.row(i) = mesh.V.row(verts[i]);
  }
  s.F.resize(F.rows(), 3);
  for (Eigen::Index f = 0; f < F.rows(); ++f)
    for (int k = 0; k < 3; ++k) s.F(f, k) = compact[F(f, k)];
  if (to_tet) *to_tet = verts;
  if (from_tet) *from_tet = std::move(compact);
  return s;
}

std::vector<int> boundary_vertices_near_region(const TetMesh& mesh, const SurfaceMesh& surface,
                                               const std::vector<int>& region_vertices, double tolerance) {
  std::vector<bool> in_region(surface.V.rows(), false);
  for (int v : region_vertices) {
    if (v < 0 || v >= surface.V.rows())
      throw InputError("region vertex " + std::to_string(v) + " out of range for a surface with " +
                       std::to_string(surface.V.rows()) + " vertices");
    in_region[v] = true;
  }
  std::vector<Eigen::Vector3i> faces;
  for (Eigen::Index f = 0; f < surface.F.rows(); ++f)
    if (in_region[surface.F(f, 0)] && in_region[surface.F(f, 1)] && in_region[surface.F(f, 2)])
      faces.emplace_back(surface.F(f, 0), surface.F(f, 1), surface.F(f, 2));
  if (faces.empty())
    throw InputError("the vertex region (" + std::to_string(region_vertices.size()) +
                     " vertices) contains no complete face of the surface; list every vertex of the chest wall");
  Triangles RF(faces.size(), 3);
  for (size_t i = 0; i < faces.size(); ++i) RF.row(i) = faces[i].transpose();
  const SurfaceClosestPoint cp(surface.V, RF);
  std::vector<int> out;
  for (int v : boundary_vertices(mesh))
    if (cp.query(mesh.V.row(v).transpose()).distance <= tolerance) out.push_back(v);
  if (out.empty())
    throw InputError("no boundary vertex of the tetrahedral mesh lies within " + std::to_string(tolerance) +
                     " m of the given vertex region");
  return out;
}

}  // namespace btr
