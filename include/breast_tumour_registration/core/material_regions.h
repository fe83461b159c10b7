// Heterogeneous tissue: per-element materials from regions (fatty and fibroglandular
// tissue, a tumour, ...). The body's material (MaterialParameters) holds everywhere a region
// does not; a region gives its tetrahedra its own Young's modulus, with the body's Poisson's
// ratio and density (breast tissues are all near-incompressible and of about water's density).
// A region selects its tetrahedra by a cell label of the prone mesh (VTK cell data, Medit
// element references) or by a closed surface (centroid inside, by winding number).
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "breast_tumour_registration/core/registration_model.h"

namespace btr {

struct MaterialRegion {
  std::string name;
  double youngs_modulus = 0;           ///< [Pa]
  std::optional<int> label;            ///< the tetrahedra with this cell label ...
  std::optional<SurfaceMesh> surface;  ///< ... or those whose centroid lies inside this closed surface (model frame)
};

/// InputError (naming `where`) unless the region has a name, a finite positive Young's
/// modulus and exactly one of label and surface.
void validate_material_region(const MaterialRegion& region, const std::string& where);

/// Gives each region's tetrahedra of the model the region's material (later regions win where
/// they overlap), appending one material per region to model.materials and counting them in
/// model.material_tetrahedra. `labels`: one per tetrahedron of the model's mesh (empty when the
/// mesh has none). InputError for a label region without labels, a label no tetrahedron
/// carries, or a surface region with no centroid inside (the mesh is too coarse for it).
void assign_material_regions(RegistrationModel& model, const std::vector<MaterialRegion>& regions,
                             const std::vector<int>& labels);

/// Cell labels of `from` carried to the tetrahedra of `to` (another mesh of the same body,
/// e.g. the simulation mesh): each takes the label of the tetrahedron of `from` holding its
/// centroid (the nearest one for a centroid outside).
std::vector<int> transfer_cell_labels(const TetMesh& from, const std::vector<int>& labels, const TetMesh& to);

}  // namespace btr
