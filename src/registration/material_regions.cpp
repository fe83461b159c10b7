#include "breast_tumour_registration/registration/material_regions.h"

#include <algorithm>
#include <cstdio>

#include "breast_tumour_registration/base/errors.h"
#include "breast_tumour_registration/geometry/embedding.h"
#include "breast_tumour_registration/geometry/metrics.h"
#include "breast_tumour_registration/geometry/validation.h"

namespace btr {

double partial_volume_youngs_modulus(double matrix, double inclusion, double fraction) {
  if (!(matrix > 0) || !(inclusion > 0) || !(fraction >= 0 && fraction <= 1))
    throw InputError("partial volume: moduli must be > 0 and the fraction in [0, 1]");
  if (inclusion == matrix) return matrix;
  return matrix * (1 + fraction / (matrix / (inclusion - matrix) + 0.4 * (1 - fraction)));
}

std::vector<std::string> assign_material_regions(RegistrationModel& model, const std::vector<MaterialRegion>& regions,
                                                 const std::vector<int>& labels) {
  std::vector<std::string> notes;
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
      const TetMesh prone{model.prone, model.rest.T};
      members = tetrahedra_inside(prone, {&*r.surface});
      if (members.empty()) {
        // Smaller than the mesh resolves: the tetrahedron holding the region's centroid takes a
        // mixture of its material and the region's by the region's share of its volume.
        const Points centroid = volume_centroid(*r.surface).transpose();
        const int t = embed_points(prone, centroid).tet[0];
        const double share = std::min(1.0, std::abs(enclosed_volume(*r.surface)) / std::abs(tet_signed_volume(prone.V, prone.T, t)));
        const StableNeoHookean& around = model.materials[static_cast<size_t>(model.material_of[t])];
        const double E = partial_volume_youngs_modulus(around.youngs_modulus(), r.youngs_modulus, share);
        model.materials.push_back(StableNeoHookean(E, model.material.poisson_ratio));
        model.material_names.push_back(r.name + " (partial volume)");
        model.material_tetrahedra.push_back(0);
        model.material_of[t] = static_cast<int>(model.materials.size()) - 1;
        char buf[160];
        std::snprintf(buf, sizeof buf, "%.2g %% of the tetrahedron holding its centroid, whose E becomes %.0f Pa (%.0f Pa before)",
                      100 * share, E, around.youngs_modulus());
        notes.push_back("regions '" + r.name + "': no tetrahedron centroid lies inside its surface (the mesh is coarser "
                        "than the region); it is " + buf + ". A finer --cell-size resolves it");
        continue;
      }
    }
    const int index = static_cast<int>(model.materials.size());
    model.materials.push_back(StableNeoHookean(r.youngs_modulus, model.material.poisson_ratio));
    model.material_names.push_back(r.name);
    model.material_tetrahedra.push_back(0);
    for (int t : members) model.material_of[t] = index;
  }
  count_material_tetrahedra(model);
  return notes;
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
