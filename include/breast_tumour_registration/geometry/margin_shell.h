// The margin shell of a tumour (issue 14): its registered surface grown outwards, vertex by
// vertex, by a local bound on where that vertex may be (e.g. the 95th percentile of its
// displacement over sampled re-registrations). A surgeon's margin drawn around the shell holds
// the tumour surface at that vertex with the bound's probability, to the extent the bound's
// sources cover what is uncertain.
#pragma once

#include <vector>

#include "breast_tumour_registration/base/types.h"

namespace btr {

/// `surface` (closed, consistently oriented, inward or outward) with vertex v moved by grow[v]
/// [m] along its outward unit normal (area-weighted over its faces). Throws InputError for a
/// size mismatch, a negative or non-finite grow value, or a surface validate_surface refuses.
SurfaceMesh margin_shell(const SurfaceMesh& surface, const std::vector<double>& grow);

}  // namespace btr
