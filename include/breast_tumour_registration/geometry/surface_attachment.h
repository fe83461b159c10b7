// Re-attaching vertex references of an input surface to a tetrahedral mesh built from
// it: each input point becomes an exact barycentric point on the tet mesh boundary.
#pragma once

#include <vector>

#include "breast_tumour_registration/base/types.h"
#include "breast_tumour_registration/geometry/anchor.h"

namespace btr {

struct BoundaryAttachment {
  std::vector<Anchor> anchors;     ///< one per input point: 3 boundary vertices + weights
  std::vector<double> distances;   ///< distance from the input point to its anchor at rest [m]
  double max_distance = 0;
};

/// Closest point on the boundary of `mesh` for every point (rows of P).
BoundaryAttachment attach_to_boundary(const TetMesh& mesh, const Points& P);

/// Boundary vertices of `mesh` within `tolerance` of the region of `surface` spanned by
/// faces whose three vertices are all in `region_vertices` (e.g. the chest wall).
/// Throws InputError if the region has no face or no boundary vertex falls within it.
std::vector<int> boundary_vertices_near_region(const TetMesh& mesh, const SurfaceMesh& surface,
                                               const std::vector<int>& region_vertices, double tolerance);

/// Sorted unique vertex indices used by the boundary faces of `mesh`.
std::vector<int> boundary_vertices(const TetMesh& mesh);

/// Closed surface made of the boundary faces of `mesh`, with its own compact vertex
/// numbering; `to_tet` (optional) receives the tet-mesh index of every surface vertex, and
/// `from_tet` (optional) the surface index of every tet-mesh vertex (-1 off the boundary).
SurfaceMesh boundary_surface(const TetMesh& mesh, std::vector<int>* to_tet = nullptr, std::vector<int>* from_tet = nullptr);

}  // namespace btr
