#include "breast_tumour_registration/registration/simulation_mesh.h"

#include <chrono>
#include <cmath>

#include "breast_tumour_registration/base/errors.h"
#include "breast_tumour_registration/base/units.h"
#include "breast_tumour_registration/geometry/surface_attachment.h"
#include "breast_tumour_registration/geometry/tetrahedralize.h"
#include "breast_tumour_registration/geometry/validation.h"
#include "breast_tumour_registration/registration/material_regions.h"

namespace btr {

namespace {
// What a meshing error with tumour refinements needs said: where their size came from.
std::string tumour_cells_context(const TetrahedralizeOptions& topt) {
  if (topt.refinements.empty()) return "";
  return " (the refinement balls are the tumours', at " + format_mm(topt.refinements.front().cell_size, 2) +
         ": prone.tumour_cell_size_mm, else the preset's)";
}
}  // namespace

Scene with_simulation_mesh(const Scene& scene, double cell_size, double tumour_cell_size) {
  if (!(cell_size > 0) || !std::isfinite(cell_size))
    throw InputError("simulation cell size must be positive, got " + std::to_string(cell_size * 1e3) + " mm");
  if (scene.prone.T.rows() == 0) {  // a prone surface not meshed yet: meshed once, at this size
    if (!scene.prone_source) throw InputError(scene.path + ": the scene has no prone model to mesh");
    Scene out = scene;
    mesh_prone(out, cell_size, tumour_cell_size);
    return out;
  }
  const auto t0 = std::chrono::steady_clock::now();
  std::vector<int> surface_index;
  const SurfaceMesh surface = boundary_surface(scene.prone, nullptr, &surface_index);
  std::vector<int> wall;
  for (int v : scene.chest_wall)
    if (surface_index[v] >= 0) wall.push_back(surface_index[v]);

  Scene out = scene;
  TetrahedralizeOptions topt;
  topt.cell_size = cell_size;
  topt.refinements = tumour_refinements(scene, cell_size, tumour_cell_size);
  try {
    out.prone = tetrahedralize(surface, topt);
  } catch (const InputError& e) {
    throw InputError(scene.path + ": re-tetrahedralizing the prone model: " + e.what() + tumour_cells_context(topt));
  }
  out.chest_wall = boundary_vertices_near_region(out.prone, surface, wall, 1e-6 + topt.facet_distance_ratio * cell_size);
  Points landmarks(static_cast<Eigen::Index>(scene.landmark_anchors.size()), 3);
  for (size_t i = 0; i < scene.landmark_anchors.size(); ++i)
    landmarks.row(static_cast<Eigen::Index>(i)) = scene.landmark_anchors[i].position(scene.prone.V).transpose();
  if (landmarks.rows()) out.landmark_anchors = attach_to_boundary(out.prone, landmarks).anchors;
  if (!scene.prone_labels.empty()) {
    TransferredLabels labels = transfer_cell_labels(scene.prone, scene.prone_labels, out.prone);
    out.prone_labels = std::move(labels.labels);
    out.prone_label_remnants = std::move(labels.remnants);
  }
  out.tetrahedralized = true;
  out.tetrahedralize_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return out;
}

std::vector<MeshRefinement> tumour_refinements(const Scene& s, double cell_size, double tumour_cell_size) {
  std::vector<MeshRefinement> out;
  if (!(tumour_cell_size > 0) || !(tumour_cell_size < cell_size)) return out;
  for (const auto& t : s.tumours) {
    if (t.prone.V.rows() == 0) continue;
    MeshRefinement b;
    b.centre = t.prone.V.colwise().mean().transpose();
    b.radius = (t.prone.V.rowwise() - b.centre.transpose()).rowwise().norm().maxCoeff();
    b.cell_size = tumour_cell_size;
    out.push_back(b);
  }
  return out;
}

double mean_edge_length_away_from_tumours(const Scene& s, double cell_size, double tumour_cell_size) {
  TetrahedralizeOptions topt;
  topt.cell_size = cell_size;
  topt.refinements = tumour_refinements(s, cell_size, tumour_cell_size);
  const double away = mean_edge_length(
      s.prone, [&](Eigen::Index t) { return cell_size_at(tet_centroid(s.prone.V, s.prone.T, t), topt) >= cell_size; });
  return away > 0 ? away : mean_edge_length(s.prone);
}

void mesh_prone(Scene& s, double cell_size, double tumour_cell_size) {
  if (!s.prone_source) throw InputError(s.path + ": the prone model is a tetrahedral mesh already");
  if (!(cell_size > 0) || !std::isfinite(cell_size))
    throw InputError(s.path + ": field 'prone.cell_size_mm': must be positive");
  const ProneSurfaceSource& src = *s.prone_source;
  TetrahedralizeOptions topt;
  topt.cell_size = cell_size;
  topt.refinements = tumour_refinements(s, cell_size, tumour_cell_size);
  const auto t0 = std::chrono::steady_clock::now();
  try {
    s.prone = tetrahedralize(src.surface, topt);
  } catch (const InputError& e) {
    throw InputError(s.path + ": field 'prone.surface': " + e.what() + tumour_cells_context(topt));
  }
  s.tetrahedralize_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  s.tetrahedralized = true;
  try {
    s.chest_wall = boundary_vertices_near_region(s.prone, src.surface, src.chest_wall, 1e-6 + topt.facet_distance_ratio * cell_size);
  } catch (const InputError& e) {
    throw InputError(s.path + ": field 'chest_wall': " + e.what());
  }
  if (src.landmarks.rows()) {
    const BoundaryAttachment a = attach_to_boundary(s.prone, src.landmarks);
    check_landmark_attachment(a, s.landmark_labels, s.path);
    s.landmark_anchors = a.anchors;
  }
}

Scene load_meshed_scene(const std::string& path) {
  Scene s = load_scene(path);
  if (s.prone_source) mesh_prone(s, s.prone_source->cell_size.value_or(kDefaultCellSize), s.tumour_cell_size.value_or(0));
  return s;
}

}  // namespace btr
