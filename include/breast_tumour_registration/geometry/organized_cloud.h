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

/// Whether `cloud` has one row per pixel of a width x height image (both > 0).
bool is_organized(const Points& cloud, int width, int height);

/// An organized cloud denoised in its image grid: each valid pixel becomes the Gaussian-weighted
/// mean (sigma `sigma_pixels`, window 3 sigma) of the valid pixels around it that lie within
/// `max_edge` [m] of it (no averaging across depth discontinuities). A depth camera's noise is
/// independent per pixel, so the surface step's closest points and normals on the denoised scan
/// jitter less. It is not free of bias: on a noise-free rendered scan of the phantom the
/// registered tumours moved by up to 0.15 mm at sigma 2 px (BENCHMARKS.md). sigma_pixels <= 0:
/// the cloud as it is. InputError when the cloud is not organized.
Points smooth_organized(const Points& cloud, int width, int height, double sigma_pixels, double max_edge = 0.01);

/// The depth noise of an organized cloud [m], estimated from second differences along its rows
/// (p - (left + right) / 2 for three valid pixels within `max_edge` of each other: on a smooth
/// surface that is curvature times the pixel spacing squared, hundredths of a millimetre, on a
/// noisy one 1.22 sigma), robustly: 1.4826 median / 1.22. NaN when no triple is valid.
double estimate_organized_noise(const Points& cloud, int width, int height, double max_edge = 0.01);

/// The finite rows of `cloud` (NaN and infinite points dropped), in order.
Points finite_points(const Points& cloud);

}  // namespace btr
