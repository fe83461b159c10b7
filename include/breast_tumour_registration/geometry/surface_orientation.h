// Repairing the face orientation of a closed triangle surface, as modelling tools often
// export it (a few faces flipped): CGAL's polygon-soup orientation makes neighbours agree,
// then the whole surface is turned outwards (positive enclosed volume).
#pragma once

#include "breast_tumour_registration/base/types.h"

namespace btr {

/// Orients `s` consistently and outwards in place; returns how many faces were flipped.
/// Throws InputError (naming `name`) when no consistent orientation exists without
/// splitting vertices (a non-manifold or non-orientable surface): that cannot be repaired.
long orient_closed_surface(SurfaceMesh& s, const std::string& name);

}  // namespace btr
