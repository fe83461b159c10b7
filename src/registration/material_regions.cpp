#include "breast_tumour_registration/registration/material_regions.h"

#include "breast_tumour_registration/base/errors.h"
#include "breast_tumour_registration/geometry/embedding.h"

namespace btr {

void assign_material_regions(RegistrationModel& model, const std::vector<MaterialRegion>& regions,
                             const std::vector<int>& labels) {
  const Eigen::Index nt = model.rest.T.rows();
  if (!labels.empty() && static_cast<Eigen::Index>(labels.size()) != nt)
    throw InputError("regions: " + std::to_string(labels.size()) + " cell labels for " + std::to_string(nt) + " tetrahedra");
  for (const MaterialRegion& r : regions) {
    validate_material_region(r, "regions");
    std::vector<int> members;
    if (r.label) {
      if (labels.empty())
        throw InputError("regions '" + r.name + "': label " + std::to_string(*r.label) +
                         " needs a prone.tet_mesh with cell labels (VTK CELL_DATA or Medit references)");
      for (Eigen::Index t = 0; t < nt; ++t)
        if (labels[t] == *r.label) members.push_back(static_cast<int>(t));
      if (members.empty())
        throw InputError("regions '" + r.name + "': no tetrahedron carries label " + std::to_string(*r.label));
    } else {
      // Given on the prone image: the centroids are taken at the prone positions.
      members = tetrahedra_inside(TetMesh{model.prone, model.rest.T}, {&*r.surface});
      if (members.empty())
        throw InputError("regions '" + r.name + "': no tetrahedron centroid lies inside its surface; refine the mesh");
    }
    const int index = static_cast<int>(model.materials.size());
    model.materials.push_back(StableNeoHookean(r.youngs_modulus, model.material.poisson_ratio));
    model.material_names.push_back(r.name);
    model.material_tetrahedra.push_back(0);
    for (int t : members) model.material_of[t] = index;
  }
  count_material_tetrahedra(model);
}

std::vector<int> transfer_cell_labels(const TetMesh& from, const std::vector<int>& labels, const TetMesh& to) {
  if (static_cast<Eigen::Index>(labels.size()) != from.T.rows())
    throw InputError("cell labels: " + std::to_string(labels.size()) + " labels for " + std::to_string(from.T.rows()) + " tetrahedra");
  Points centroids(to.T.rows(), 3);
  for (Eigen::Index t = 0; t < to.T.rows(); ++t) {
    Vec3 c = Vec3::Zero();
    for (int k = 0; k < 4; ++k) c += to.V.row(to.T(t, k)).transpose();
    centroids.row(t) = 0.25 * c.transpose();
  }
  const Embedding e = embed_points(from, centroids, OutsidePolicy::NearestTetrahedron);
  std::vector<int> out(to.T.rows());
  for (Eigen::Index t = 0; t < to.T.rows(); ++t) out[t] = labels[e.tet[t]];
  return out;
}

}  // namespace btr
