// Unit vertex normals of a triangle surface, area-weighted over the incident faces (the
// direction a depth camera's noise moves a vertex).
#pragma once

#include <functional>

#include "breast_tumour_registration/base/types.h"

namespace btr {

/// #V by 3, unit rows; a vertex on no face of non-zero area gets a zero row.
Points vertex_normals(const SurfaceMesh& s);

/// Depth noise: every vertex moved along its normal by sd times a draw of standard_normal (one
/// draw per vertex, in vertex order, so that a seeded stream gives the same surface).
void displace_along_normals(SurfaceMesh& s, double sd, const std::function<double()>& standard_normal);

}  // namespace btr
