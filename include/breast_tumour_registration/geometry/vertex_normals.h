// Unit vertex normals of a triangle surface, area-weighted over the incident faces (the
// direction a depth camera's noise moves a vertex).
#pragma once

#include "breast_tumour_registration/base/types.h"

namespace btr {

/// #V by 3, unit rows; a vertex on no face of non-zero area gets a zero row.
Points vertex_normals(const SurfaceMesh& s);

}  // namespace btr
