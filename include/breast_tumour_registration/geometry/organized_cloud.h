// An organized depth cloud (one point per pixel, row-major, NaN where the sensor saw
// nothing) as a surface: what the surface-guided step needs from a depth camera (closest
// points with normals), and the finite points of any cloud.
#pragma once

#include "breast_tumour_registration/base/types.h"

namespace btr {

/// Triangulates an organized cloud (width * height rows, NaN = no data): two triangles per
/// 2x2 pixel block whose corners are valid and whose edges are shorter than `max_edge` [m]
/// (no faces across depth discontinuities). Unused points are dropped. Throws InputError
/// when the cloud is not organized (rows != width * height) or yields no face.
SurfaceMesh triangulate_organized(const Points& cloud, int width, int height, double max_edge = 0.01);

/// The finite rows of `cloud` (NaN and infinite points dropped), in order.
Points finite_points(const Points& cloud);

}  // namespace btr
