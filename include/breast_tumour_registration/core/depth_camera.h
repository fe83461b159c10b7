// A pinhole depth camera: renders surfaces as a depth sensor would see them (first hit
// along each pixel ray, CGAL AABB tree), for generating depth scans and bags without a
// sensor; and the triangulation of an organized depth cloud back into a surface, which
// the surface-guided step needs (closest points with normals).
#pragma once

#include <random>
#include <vector>

#include "breast_tumour_registration/core/rigid_transform.h"

namespace btr {

/// Pinhole intrinsics; the camera looks along +z of its frame, x right, y down (REP 103
/// optical frame).
struct PinholeCamera {
  int width = 640, height = 480;
  double fx = 525, fy = 525, cx = 319.5, cy = 239.5;  ///< [px]
  double min_range = 0.1, max_range = 3.0;            ///< [m]
};

/// Organized cloud: width * height rows (row-major pixels) in the camera frame; pixels
/// without a hit are NaN. `camera_to_world` places the camera; surfaces are in world.
Points render_depth(const std::vector<const SurfaceMesh*>& surfaces, const PinholeCamera& cam,
                    const Rigid& camera_to_world);

/// Adds Gaussian noise of `sigma` [m] along each pixel's ray (depth noise), in place.
void add_depth_noise(Points& cloud, double sigma, std::mt19937& rng);

/// A camera pose looking at `target` from `eye` (world frame), with `up` roughly up in the image.
Rigid look_at(const Vec3& eye, const Vec3& target, const Vec3& up);

/// Triangulates an organized cloud (width * height rows, NaN = no data): two triangles per
/// 2x2 pixel block whose corners are valid and whose edges are shorter than `max_edge` [m]
/// (no faces across depth discontinuities). Unused points are dropped. Throws InputError
/// when the cloud is not organized (rows != width * height) or yields no face.
SurfaceMesh triangulate_organized(const Points& cloud, int width, int height, double max_edge = 0.01);

}  // namespace btr
