// The simulation mesh as a speed/accuracy knob: the prone model re-tetrahedralized from its
// boundary surface at another cell size. The tumours are embedded in whatever mesh the model
// uses, so a coarser simulation mesh keeps the tumour geometry and only coarsens the
// deformation field (BENCHMARKS.md measures the trade).
#pragma once

#include "breast_tumour_registration/io/scene.h"

namespace btr {

/// The scene with its prone model re-tetrahedralized at `cell_size` [m]: the chest wall is
/// found again on the new boundary and the landmarks are re-attached as barycentric anchors,
/// the cell labels carried over (transfer_cell_labels);
/// all other data is unchanged (prepare_model embeds the tumours in the new mesh). Throws
/// InputError for cell_size <= 0 or a prone boundary that cannot be meshed.
Scene with_simulation_mesh(const Scene& scene, double cell_size);

}  // namespace btr
