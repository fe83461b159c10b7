// Figures of merit of a registration (thesis Sec. 5.2.1: tumour centroid distance), plus
// Hausdorff distance and volume ratio of the tumour, landmark residuals and skin distance.
#pragma once

#include <vector>

#include "breast_tumour_registration/base/types.h"

namespace btr {

/// Volume of a closed, outward-oriented surface [m^3] (divergence theorem).
double enclosed_volume(const SurfaceMesh& s);
/// Volume centroid of a closed surface: independent of how the surface is sampled.
Vec3 volume_centroid(const SurfaceMesh& s);
/// d volume_centroid / d s.V: 3 by 3#V, column 3 v + k the derivative by coordinate k of vertex v.
Eigen::MatrixXd volume_centroid_jacobian(const SurfaceMesh& s);
/// Shape of a closed surface's volume: sqrt(smallest / largest eigenvalue of its second
/// moment), i.e. shortest over longest principal axis; 1 for a sphere, < 1 when flattened.
double principal_axis_ratio(const SurfaceMesh& s);
/// Symmetric Hausdorff distance between two surfaces (vertex-to-surface, both ways) [m].
double hausdorff_distance(const SurfaceMesh& a, const SurfaceMesh& b);
/// Distances from every point to the surface [m].
std::vector<double> point_to_surface_distances(const Points& P, const SurfaceMesh& s);

struct DistanceStats {
  double mean = 0, max = 0, rms = 0;
};
DistanceStats distance_stats(const std::vector<double>& d);

}  // namespace btr
