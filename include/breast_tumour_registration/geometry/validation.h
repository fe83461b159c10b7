// Geometric validation of meshes with messages that say what is wrong and where.
#pragma once

#include <functional>

#include <string>

#include "breast_tumour_registration/base/types.h"

namespace btr {

struct SurfaceCheckOptions {
  bool require_closed = true;  ///< every edge shared by exactly two faces
  bool require_consistent_orientation = true;
};

/// Throws InputError for: no faces, NaN/Inf coordinates, indices out of range,
/// degenerate (zero-area or repeated-vertex) faces, non-manifold edges, open boundary
/// edges (when required) and inconsistently oriented neighbours (when required).
/// `name` prefixes the message (e.g. the file name).
void validate_surface(const SurfaceMesh& mesh, const std::string& name, const SurfaceCheckOptions& opt = {});

/// Signed volume of tetrahedron t (positive for the library's orientation).
double tet_signed_volume(const Points& V, const Tetrahedra& T, Eigen::Index t);

/// Centroid of tetrahedron t [m].
Vec3 tet_centroid(const Points& V, const Tetrahedra& T, Eigen::Index t);

/// Mean length of the six edges of every tetrahedron (indices must be in range) [m].
double mean_edge_length(const TetMesh& m);
/// The same over the tetrahedra `keep` accepts (0 where it accepts none) [m].
double mean_edge_length(const TetMesh& m, const std::function<bool(Eigen::Index)>& keep);

/// Flips every tetrahedron when all are negatively oriented (a file convention);
/// returns true when it did. Mixed orientations are left for validate_tet_mesh to reject.
bool orient_tets_positive(TetMesh& mesh);

/// Throws InputError for: no tetrahedra, NaN/Inf coordinates, indices out of range,
/// repeated vertices in a tetrahedron, inverted tetrahedra, and degenerate
/// tetrahedra (|volume| below `degenerate_rel` times the cube of the mean edge length).
void validate_tet_mesh(const TetMesh& mesh, const std::string& name, double degenerate_rel = 1e-8);

/// Boundary faces of a tet mesh (faces used by one tetrahedron), oriented outwards.
Triangles boundary_faces(const TetMesh& mesh);

}  // namespace btr
