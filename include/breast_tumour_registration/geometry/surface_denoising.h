// A noisy supine mesh (a scanner's surface, a reconstructed depth mesh, the calibration's
// noisy copies) denoised along its normals before the surface step projects onto it.
//
// Each vertex is moved along its normal onto a local quadric (a height field in its own tangent
// frame over its 2-ring, and on a dense mesh over whatever lies within 4 noise sds) fitted by
// iteratively reweighted least squares: spatial weights a Gaussian of the tangent distance
// (sigma: the mesh's median edge length, or twice the noise where larger), range weights a
// Gaussian of each neighbour's residual (sigma: range_factor times the noise), and only
// neighbours whose smoothed normal is within acos(normal_cos) of the vertex's take part. So the
// skin's curvature is kept (a quadric fits it: on the noise-free SfePy scan the filter, told of
// 0.25 mm of noise, moves vertices by 0.03 mm RMS), and where the skin meets the chest wall at
// a crease the other side is left out instead of being averaged in, and the crease's own
// vertices stay. CGAL's jet smoothing (a quadric without the range and normal weights) moved
// that crease by up to 2.5 mm on the noise-free scan, and its bilateral point-set smoothing slid
// points along the surface and left a noisy copy farther from the truth (BENCHMARKS.md, issue
// 14, 2026-12-05): hence this filter.
#pragma once

#include "breast_tumour_registration/base/types.h"

namespace btr {

/// The noise of a surface mesh along its normals [m]. Each vertex's height above the quadric
/// fitted to its 2-ring neighbours (the vertex left out) is noise plus what the quadric misses
/// of the shape; over each edge the difference of its two ends' heights, divided by the sd it
/// has under independent noise of sd 1 (the fits share vertices; computed from the fits'
/// weights), has the noise's sd, and a smooth shape's remainder cancels in it. Robustly:
/// 1.4826 times the median of their absolute values. 1 mm of noise reads 0.99 to 1.13 mm on the
/// phantom's and SfePy's scans; noise-free scans read 0.01 to 0.03 mm (SfePy), 0.07 to 0.09 mm
/// (the TetGen body) and 0.02 to 0.23 mm (the 8 mm phantom, 12 000 to 300 Pa): the facets of a
/// coarse, strongly deformed mesh are roughness at the scale of a vertex, like noise (0.54 to
/// 0.58 mm on the 12 mm phantom at 200 to 300 Pa). NaN when fewer than 10 edges can be used.
double estimate_surface_noise(const SurfaceMesh& s);

struct SurfaceDenoisingOptions {
  int iterations = 3;          ///< passes (each from the previous pass's positions and normals)
  double range_factor = 2.0;   ///< range weights' sigma, in units of the noise
  double normal_cos = 0.7;     ///< neighbours with a smoothed normal farther than acos(this) are left out
  double crease_cos = 0.5;     ///< a vertex whose 1-ring's smoothed normals differ by more than acos(this) stays
  double max_move = 3.0;       ///< a pass moves a vertex at most this many noise sds
};

/// `s` with each vertex moved along its normal as above, for a mesh whose noise along its
/// normals is `noise` [m] (> 0; estimate_surface_noise gives it). Crease vertices, and vertices
/// with fewer than 8 neighbours that agree in normal (a tip), stay where they are. The
/// faces are kept. InputError for a noise that is not a positive number or options out of range.
SurfaceMesh denoise_surface(const SurfaceMesh& s, double noise, const SurfaceDenoisingOptions& opt = {});

}  // namespace btr
