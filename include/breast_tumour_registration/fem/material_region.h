// One region of heterogeneous tissue (fatty or fibroglandular tissue, a tumour, ...) as a
// scene gives it: its own Young's modulus, with the body's Poisson's ratio and density (breast
// tissues are all near-incompressible and of about water's density), on the tetrahedra it
// selects by a cell label of the prone mesh (VTK cell data, Medit element references) or by a
// closed surface (centroid inside, by winding number). material_regions.h assigns them.
#pragma once

#include <optional>
#include <string>

#include "breast_tumour_registration/base/types.h"

namespace btr {

struct MaterialRegion {
  std::string name;
  double youngs_modulus = 0;           ///< [Pa]
  std::optional<int> label;            ///< the tetrahedra with this cell label ...
  std::optional<SurfaceMesh> surface;  ///< ... or those whose centroid lies inside this closed surface (model frame)
};

/// A cell label that a mesh of the body carries on no tetrahedron (after transfer_cell_labels:
/// the labelled region is smaller than the new cells): where it was and how much of it, so the
/// tetrahedron holding it can take its share (assign_material_regions).
struct LabelRemnant {
  int label = 0;
  Vec3 centroid = Vec3::Zero();  ///< volume centroid of the labelled tetrahedra [m]
  double volume = 0;             ///< their volume [m^3]
};

/// InputError (naming `where`) unless the region has a name, a finite positive Young's
/// modulus and exactly one of label and surface (a valid closed surface).
void validate_material_region(const MaterialRegion& region, const std::string& where);

}  // namespace btr
