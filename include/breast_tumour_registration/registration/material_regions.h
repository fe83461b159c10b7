// Heterogeneous tissue: per-element materials from regions (material_region.h). The body's
// material (MaterialParameters) holds everywhere a region does not.
#pragma once

#include <string>
#include <vector>

#include "breast_tumour_registration/fem/material_region.h"
#include "breast_tumour_registration/registration/registration_model.h"

namespace btr {

/// Gives each region's tetrahedra of the model the region's material (later regions win where
/// they overlap), appending one material per region to model.materials and counting them in
/// model.material_tetrahedra. `labels`: one per tetrahedron of the model's mesh (empty when the
/// mesh has none). A surface region with no tetrahedron centroid inside (smaller than the mesh
/// resolves: a small tumour on a preset's 9 or 11 mm mesh) gives the tetrahedron holding its
/// centroid the partial-volume mixture of that tetrahedron's material and its own, and a note
/// (returned, for the warnings); before, it was an error. So does a label region that a re-mesh
/// left on no tetrahedron (one of `remnants`: a 16 mm tumour label on the fast preset's cells).
/// InputError for a label region without labels or a label no tetrahedron carries otherwise.
std::vector<std::string> assign_material_regions(RegistrationModel& model, const std::vector<MaterialRegion>& regions,
                                                 const std::vector<int>& labels, const std::vector<LabelRemnant>& remnants = {});

/// Young's modulus of a tetrahedron of `matrix` [Pa] holding a `fraction` of its volume of an
/// `inclusion` [Pa]: the Hashin-Shtrikman bound with the matrix as reference for nearly
/// incompressible phases (the dilute estimate for a spherical inclusion, E (1 + 2.5 f) for a
/// rigid one; the volume average would give a stiff one's whole modulus times its share).
double partial_volume_youngs_modulus(double matrix, double inclusion, double fraction);

struct TransferredLabels {
  std::vector<int> labels;               ///< one per tetrahedron of `to`
  std::vector<LabelRemnant> remnants;    ///< labels of `from` that no tetrahedron of `to` took
};

/// Cell labels of `from` carried to the tetrahedra of `to` (another mesh of the same body,
/// e.g. the simulation mesh): each takes the label of the tetrahedron of `from` holding its
/// centroid (the nearest one for a centroid outside). A label whose region no centroid of `to`
/// falls in is returned as a remnant.
TransferredLabels transfer_cell_labels(const TetMesh& from, const std::vector<int>& labels, const TetMesh& to);

}  // namespace btr
