// Barycentric embedding of points (e.g. tumour mesh vertices) in a tetrahedral mesh and
// their reconstruction from deformed vertex positions (thesis Sec. 4.2).
#pragma once

#include <vector>

#include "breast_tumour_registration/base/types.h"

namespace btr {

/// What to do with a point outside the tetrahedral mesh.
enum class OutsidePolicy {
  /// Attach it to the tetrahedron under its closest boundary point, with (partly
  /// negative) barycentric coordinates: it then moves with that tetrahedron's affine
  /// map. Counted in Embedding::outside and reported by the caller as a warning.
  NearestTetrahedron,
  /// Throw InputError naming the first outside point.
  Error,
};

struct Embedding {
  Eigen::VectorXi tet;                                    ///< #P containing (or nearest) tetrahedron
  Eigen::Matrix<double, Eigen::Dynamic, 4, Eigen::RowMajor> weights;  ///< #P by 4 barycentric weights
  std::vector<int> outside;                               ///< indices of points outside the mesh
  double max_outside_distance = 0;                        ///< [m]
};

/// P #P by 3 points [m]; `tolerance` (relative barycentric slack) decides "inside".
Embedding embed_points(const TetMesh& mesh, const Points& P, OutsidePolicy policy = OutsidePolicy::NearestTetrahedron,
                       double tolerance = 1e-9);

/// Whether p is inside the closed surface s (winding number above 1/2; robust to how the
/// surface is sampled). O(#faces) per query.
bool inside_closed_surface(const SurfaceMesh& s, const Vec3& p);

/// Tetrahedra of `mesh` whose centroid lies inside any of the closed `surfaces` (winding
/// number), e.g. the elements of a tumour that get their own material.
std::vector<int> tetrahedra_inside(const TetMesh& mesh, const std::vector<const SurfaceMesh*>& surfaces);

/// Positions of the embedded points for deformed vertex positions x (#V by 3).
Points apply_embedding(const Embedding& e, const Tetrahedra& T, const Points& x);

}  // namespace btr
