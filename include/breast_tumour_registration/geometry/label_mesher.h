// Multi-material tetrahedral mesh of a segmented breast, meshed directly from the label map
// with CGAL Mesh_3 (a labelled image domain: every tissue label is a subdomain, the
// interfaces between labels are surface patches; the lines where three labels meet are
// protected as features, so the chest wall's rim and the tumour's contact lines stay sharp).
//
// What comes out, in RAS [m] (label_volume.h):
// - the tetrahedra of the tissue labels (fat, gland, skin, tumour), each with its label;
// - the chest wall: the corners of the facets on the interface with the muscle label (along the
//   rim a few of them lie on the skin, up to 2.5 mm above the interface at 7 mm cells; fixing
//   only the vertices Mesh_3 placed on the interface itself inverted a rim element in the
//   surface step on every mesh size tried, BENCHMARKS.md), or, without one,
//   the posterior-most boundary vertices (within half a cell of the most posterior one
//   along `posterior`);
// - every tumour as a closed surface, outward: each tumour label is meshed again on its own in
//   a box around it at tumour_facet_size, and each connected component of its surface is one
//   tumour. The simulation mesh has one size everywhere (cell_size), so that the presets,
//   which compare sizes by the mean edge, take it as it is; its tumour tetrahedra keep their
//   label for the materials.
#pragma once

#include <set>
#include <string>
#include <vector>

#include "breast_tumour_registration/base/types.h"
#include "breast_tumour_registration/geometry/label_volume.h"

namespace btr {

struct LabelMeshOptions {
  std::set<int> tissue;          ///< labels meshed as breast tissue (tumour labels included or not: they are added)
  std::set<int> tumour;          ///< labels of tumours (meshed, and each component returned as a surface)
  int muscle = -1;               ///< the pectoral muscle label (not meshed: its interface is the chest wall); -1: none
  Vec3 posterior = Vec3(0, -1, 0);  ///< RAS direction towards the chest, used without a muscle label
  double cell_size = 0.007;      ///< tetrahedron, facet and feature-edge size bound [m] (the balanced preset's)
  double tumour_facet_size = 0.0015;  ///< facet size bound of the tumours' surfaces [m]
  double facet_distance_ratio = 0.1;  ///< surface approximation error relative to cell_size
  double facet_angle = 25.0;     ///< [deg]
  double radius_edge_ratio = 2.0;
  bool protect_features = true;  ///< protect the lines where three labels meet
  double max_anisotropy = 5.0;   ///< largest voxel spacing over the smallest accepted
  std::string source = "label map";  ///< names the input in messages (its path)
};

struct LabelledTetMesh {
  TetMesh mesh;                        ///< RAS [m], positively oriented
  std::vector<int> labels;             ///< one label value per tetrahedron
  std::vector<int> chest_wall;         ///< fixed vertex indices
  bool chest_wall_from_muscle = false; ///< false: the posterior plane rule chose it
  struct Tumour {
    int label = 0;
    SurfaceMesh surface;               ///< closed, outward, RAS [m]
  };
  std::vector<Tumour> tumours;         ///< ordered by label, then by size (largest first)
  double seconds = 0;                  ///< meshing time
};

/// Meshes `v`. InputError (naming opt.source) for: options out of range; a label in
/// opt.tissue, opt.tumour or opt.muscle that no voxel carries; no tissue voxel; voxels more
/// anisotropic than opt.max_anisotropy; a mesh estimated above kMaxTetrahedra before meshing;
/// no tetrahedra or no chest wall afterwards.
LabelledTetMesh mesh_label_volume(const LabelVolume& v, const LabelMeshOptions& opt);

}  // namespace btr
