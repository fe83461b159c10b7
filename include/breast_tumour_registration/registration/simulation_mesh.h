// Meshing a scene's prone model: a prone surface tetrahedralized (the loader meshes nothing),
// and the simulation mesh as a speed/accuracy knob: the prone model re-tetrahedralized from its
// boundary surface at another cell size. The tumours are embedded in whatever mesh the model
// uses, so a coarser simulation mesh keeps the tumour geometry and only coarsens the
// deformation field (BENCHMARKS.md measures the trade).
#pragma once

#include <vector>

#include "breast_tumour_registration/geometry/tetrahedralize.h"
#include "breast_tumour_registration/io/scene.h"

namespace btr {

/// The scene with its prone model re-tetrahedralized at `cell_size` [m] (and `tumour_cell_size`
/// around its tumours: tumour_refinements): the chest wall is
/// found again on the new boundary and the landmarks are re-attached as barycentric anchors,
/// the cell labels carried over (transfer_cell_labels);
/// all other data is unchanged (prepare_model embeds the tumours in the new mesh). A scene whose
/// prone surface is not meshed yet is meshed at `cell_size` (mesh_prone). Throws InputError for
/// cell_size <= 0 or a prone boundary that cannot be meshed. A caller with registration options
/// passes tumour_cell_size_for(scene, opt); one without, the scene's own (value_or(0)).
Scene with_simulation_mesh(const Scene& scene, double cell_size, double tumour_cell_size);

/// Tetrahedralizes a scene's prone surface (s.prone_source) at cell_size [m] and attaches the
/// chest wall and the landmarks to the tetrahedra. InputError naming the field on failure, or
/// when the prone model is a tetrahedral mesh already. With tumour_cell_size below cell_size,
/// finer cells in each tumour's bounding ball, graded to cell_size around it (tumour_refinements).
void mesh_prone(Scene& s, double cell_size, double tumour_cell_size);

/// One MeshRefinement per tumour of the scene (its prone surface's bounding ball about the
/// vertex mean) with tumour_cell_size [m]; none where that is 0 or not below cell_size.
std::vector<MeshRefinement> tumour_refinements(const Scene& s, double cell_size, double tumour_cell_size);

/// Mean edge length of the scene's prone mesh away from its tumours' refined balls and their
/// graded shells at cell_size (tumour_refinements; the whole mesh where nothing lies outside
/// them) [m]: the size it was meshed at, which a mesh refined around its tumours would
/// otherwise understate (and be meshed again).
double mean_edge_length_away_from_tumours(const Scene& s, double cell_size, double tumour_cell_size);

/// load_scene, then a prone surface meshed at its prone.cell_size_mm (else kDefaultCellSize) and
/// its own prone.tumour_cell_size_mm (a preset's is not applied):
/// for callers that need the tetrahedra without an engine (which meshes at the size a call
/// simulates instead).
Scene load_meshed_scene(const std::string& path);

}  // namespace btr
