// Heterogeneous tissue: per-element materials from regions (material_region.h). The body's
// material (MaterialParameters) holds everywhere a region does not.
#pragma once

#include <vector>

#include "breast_tumour_registration/fem/material_region.h"
#include "breast_tumour_registration/registration/registration_model.h"

namespace btr {

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
