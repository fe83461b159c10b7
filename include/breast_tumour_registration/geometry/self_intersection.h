// Whether a closed triangle surface crosses itself (CGAL's polygon-mesh-processing test on
// exact predicates). A surface made of deformed mesh vertices, such as a simulated skin, can
// fold through itself where its elements did; the validation of validation.h does not see it
// (it checks connectivity and orientation, not geometry), and a tetrahedralizer given such a
// surface meshes an ill-defined inside.
#pragma once

#include "breast_tumour_registration/base/types.h"

namespace btr {

/// Number of pairs of faces of `s` that intersect other than at the edges or vertex they share.
/// `s` must be a triangle surface with indices in range (validate_surface).
long self_intersecting_face_pairs(const SurfaceMesh& s);

}  // namespace btr
