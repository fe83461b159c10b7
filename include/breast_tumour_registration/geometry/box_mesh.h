// Structured tetrahedral meshes of boxes (6 tetrahedra per cell, Freudenthal/Kuhn
// split, conforming across cells) for tests, benchmarks and closed-form checks.
#pragma once

#include "breast_tumour_registration/base/types.h"

namespace btr {

/// Box [origin, origin + size] with nx * ny * nz cells; vertex (i,j,k) has index
/// i + (nx+1) (j + (ny+1) k). Throws InputError for non-positive counts or sizes.
TetMesh make_box_tet_mesh(int nx, int ny, int nz, const Vec3& size, const Vec3& origin = Vec3::Zero());

}  // namespace btr
