#include "breast_tumour_registration/registration/material_regions.h"

#include <algorithm>
#include <cstdio>
#include <map>
#include <set>

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

namespace {
// A region smaller than the mesh resolves: the tetrahedron holding its centroid takes a mixture
// of its material and the region's by the region's share of its volume. Returns the note.
std::string mix_into_holding_tetrahedron(RegistrationModel& model, const MaterialRegion& r, const Vec3& centroid,
                                         double volume, const std::string& why) {
  const TetMesh prone{model.prone, model.rest.T};
  const int t = embed_points(prone, Points(centroid.transpose())).tet[0];
  const double share = std::min(1.0, volume / std::abs(tet_signed_volume(prone.V, prone.T, t)));
  const StableNeoHookean& around = model.materials[static_cast<size_t>(model.material_of[t])];
  const double E = partial_volume_youngs_modulus(around.youngs_modulus(), r.youngs_modulus, share);
  model.materials.push_back(StableNeoHookean(E, model.material.poisson_ratio));
  model.material_names.push_back(r.name + " (partial volume)");
  model.material_tetrahedra.push_back(0);
  model.material_of[t] = static_cast<int>(model.materials.size()) - 1;
  char buf[160];
  std::snprintf(buf, sizeof buf, "%.2g %% of the tetrahedron holding its centroid, whose E becomes %.0f Pa (%.0f Pa before)",
                100 * share, E, around.youngs_modulus());
  return "regions '" + r.name + "': " + why + "; it is " + buf + ". A finer --cell-size resolves it";
}
}  // namespace

std::vector<std::string> assign_material_regions(RegistrationModel& model, const std::vector<MaterialRegion>& regions,
                                                 const std::vector<int>& labels, const std::vector<LabelRemnant>& remnants) {
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
      if (members.empty()) {
        const auto remnant =
            std::find_if(remnants.begin(), remnants.end(), [&](const LabelRemnant& x) { return x.label == *r.label; });
        if (remnant == remnants.end())
          throw InputError("regions '" + r.name + "': no tetrahedron carries label " + std::to_string(*r.label));
        notes.push_back(mix_into_holding_tetrahedron(
            model, r, remnant->centroid, remnant->volume,
            "the re-meshed model's cells are coarser than its label's tetrahedra (no centroid falls in them)"));
        continue;
      }
    } else {
      // Given on the prone image: the centroids are taken at the prone positions.
      const TetMesh prone{model.prone, model.rest.T};
      members = tetrahedra_inside(prone, {&*r.surface});
      if (members.empty()) {
        notes.push_back(mix_into_holding_tetrahedron(model, r, volume_centroid(*r.surface), std::abs(enclosed_volume(*r.surface)),
                                                     "no tetrahedron centroid lies inside its surface (the mesh is coarser "
                                                     "than the region)"));
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

TransferredLabels transfer_cell_labels(const TetMesh& from, const std::vector<int>& labels, const TetMesh& to) {
  if (static_cast<Eigen::Index>(labels.size()) != from.T.rows())
    throw InputError("cell labels: " + std::to_string(labels.size()) + " labels for " + std::to_string(from.T.rows()) + " tetrahedra");
  Points centroids(to.T.rows(), 3);
  for (Eigen::Index t = 0; t < to.T.rows(); ++t) {
    Vec3 c = Vec3::Zero();
    for (int k = 0; k < 4; ++k) c += to.V.row(to.T(t, k)).transpose();
    centroids.row(t) = 0.25 * c.transpose();
  }
  const Embedding e = embed_points(from, centroids, OutsidePolicy::NearestTetrahedron);
  TransferredLabels out;
  out.labels.resize(static_cast<size_t>(to.T.rows()));
  std::set<int> taken;
  for (Eigen::Index t = 0; t < to.T.rows(); ++t) taken.insert(out.labels[t] = labels[e.tet[t]]);
  std::map<int, LabelRemnant> lost;
  for (Eigen::Index t = 0; t < from.T.rows(); ++t) {
    if (taken.count(labels[t])) continue;
    LabelRemnant& r = lost[labels[t]];
    r.label = labels[t];
    const double v = std::abs(tet_signed_volume(from.V, from.T, t));
    r.centroid += v * tet_centroid(from.V, from.T, t);
    r.volume += v;
  }
  for (auto& [label, r] : lost) {
    r.centroid /= r.volume;
    out.remnants.push_back(r);
  }
  return out;
}

}  // namespace btr
