// Projection onto the supine surface for the surface-guided step: a point's closest point
// and the surface normal there. The supine data is a triangle mesh (CGAL AABB tree) or an
// unorganized point cloud (nearest point, normal from the PCA of its neighbours, PCL kd-tree).
#pragma once

#include <memory>

#include "breast_tumour_registration/base/types.h"

namespace btr {

struct Projection {
  Vec3 point;        ///< closest point [m]
  Vec3 normal;       ///< unit surface normal there (sign irrelevant for point-to-plane)
  double distance;   ///< [m]
  /// The closest point lies on the border of an open surface (a scan's edge or hole):
  /// the true partner of the query is then most likely not in the scan at all (hidden from
  /// the camera), so the constraint would pull it to the border.
  bool on_boundary = false;
};

class SurfaceProjector {
 public:
  virtual ~SurfaceProjector() = default;
  virtual Projection project(const Vec3& p) const = 0;
};

/// The normal a mesh projector gives with its closest point.
enum class MeshNormals {
  Face,          ///< the closest triangle's normal: jumps where the closest point crosses an edge
  Interpolated,  ///< the area-weighted vertex normals blended by the closest point's barycentric
                 ///< weights: continuous across edges, so the point-to-plane constraint moves
                 ///< continuously with the skin
};

/// Projector onto a triangle mesh; flags closest points on its border edges (edges of a
/// single triangle).
std::unique_ptr<SurfaceProjector> make_mesh_projector(const SurfaceMesh& mesh, MeshNormals normals = MeshNormals::Face);
/// Projector onto a point cloud: nearest point, normal from the PCA of its `neighbours`
/// nearest points. Throws InputError for fewer than neighbours + 1 points or NaN points.
std::unique_ptr<SurfaceProjector> make_cloud_projector(const Points& cloud, int neighbours = 12);

}  // namespace btr
