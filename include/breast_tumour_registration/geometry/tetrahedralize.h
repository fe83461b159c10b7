// Tetrahedralization of a closed surface with CGAL Mesh_3 (Delaunay refinement with
// sharp-feature protection, then perturbation and exudation to remove slivers).
// Mesh_3 remeshes the boundary, so input vertices are generally not kept: references to
// them (landmarks, chest wall) are re-attached with surface_attachment.h.
#pragma once

#include <vector>

#include "breast_tumour_registration/base/types.h"

namespace btr {

/// A ball where the mesh is finer (a tumour and the tissue around it): cells of at most
/// `cell_size` inside, growing by TetrahedralizeOptions::refinement_grading per unit distance
/// outside, up to the global cell size.
struct MeshRefinement {
  Vec3 centre = Vec3::Zero();  ///< [m]
  double radius = 0;           ///< [m]
  double cell_size = 0;        ///< [m], below TetrahedralizeOptions::cell_size
};

struct TetrahedralizeOptions {
  double cell_size = 0.008;          ///< target edge / circumradius bound [m]
  double radius_edge_ratio = 2.0;    ///< circumradius / shortest edge bound (TetGen's -q)
  double facet_distance_ratio = 0.1; ///< surface approximation error, relative to cell_size
  double facet_angle = 25.0;         ///< minimum boundary triangle angle [deg]
  double feature_angle = 60.0;       ///< dihedral angle below which an edge is sharp [deg]
  bool optimize = true;              ///< perturb and exude slivers
  std::vector<MeshRefinement> refinements{};  ///< finer cells in these balls (the skin keeps cell_size)
  double refinement_grading = 0.5;   ///< growth of the cell size per unit distance outside a ball
};

/// The cell-size bound at x [m]: opt.cell_size, finer in and around opt.refinements (each ball's
/// size, growing by opt.refinement_grading per unit distance outside it).
double cell_size_at(const Vec3& x, const TetrahedralizeOptions& opt);

struct TetQuality {
  double max_radius_edge = 0;     ///< worst circumradius / shortest edge
  double median_radius_edge = 0;
  double min_dihedral_deg = 0;    ///< smallest dihedral angle [deg]
  double min_volume = 0;          ///< [m^3]
};

/// The largest mesh this package makes (about 3 GB through meshing and solving).
constexpr double kMaxTetrahedra = 3e6;

/// Tetrahedralizes the volume bounded by `surface` (closed, consistently oriented; call
/// validate_surface first). Output tetrahedra are positively oriented. Throws InputError
/// for bad options, for a cell size whose estimated mesh exceeds kMaxTetrahedra (before any
/// meshing), or when meshing produces no tetrahedra.
TetMesh tetrahedralize(const SurfaceMesh& surface, const TetrahedralizeOptions& opt);

TetQuality tet_quality(const TetMesh& mesh);

}  // namespace btr
