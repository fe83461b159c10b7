// A pinhole depth camera: renders surfaces as a depth sensor would see them (first hit
// along each pixel ray, CGAL AABB tree), for generating depth scans and bags without a
// sensor (geometry/organized_cloud.h triangulates them back into a surface).
#pragma once

#include <random>
#include <vector>

#include "breast_tumour_registration/geometry/rigid_transform.h"

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

}  // namespace btr
