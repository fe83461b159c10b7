// Rigid refinement with PCL ICP (point-to-plane, median-distance correspondence rejection,
// voxel-downsampled clouds; normals estimated on both, or a target with known normals
// prepared once) behind an interface without PCL types, so that only icp_alignment.cpp
// pays PCL's compile time. Its result is checked (convergence and inlier RMS), never
// trusted blindly.
#pragma once

#include <memory>
#include <optional>
#include <string>

#include "breast_tumour_registration/geometry/rigid_transform.h"

namespace btr {

struct IcpOptions {
  int max_iterations = 40;
  double max_correspondence_distance = 0.01;  ///< [m] of the final (fine) pass
  /// [m] a first pass with this wider radius captures larger initial offsets; <= 0: none.
  double coarse_correspondence_distance = 0.05;
  double voxel_size = 0.003;                  ///< [m] downsampling; <= 0: none
  int normal_neighbours = 12;
  double transformation_epsilon = 1e-10;
  double median_factor = 3.0;       ///< reject correspondences beyond this times the median distance
  double max_inlier_rms = 0.002;    ///< [m] accept only below this
  double min_overlap = 0.3;         ///< accept only when this fraction of source points has a correspondence
};

struct IcpResult {
  Rigid transform = Rigid::Identity();  ///< maps source points onto the target (includes `initial`)
  bool converged = false;     ///< PCL's own verdict
  bool accepted = false;      ///< converged and within the RMS and overlap bounds
  double inlier_rms = 0;      ///< [m] RMS distance of correspondences within max distance
  double overlap = 0;         ///< fraction of source points within max distance after alignment
  int iterations = 0;
  double seconds = 0;
  std::string message;        ///< why it was (not) accepted
  /// How well the fit determines the pose: the covariance of a small motion xi = (omega, tau)
  /// [rad, m] applied after `transform` in the target frame (transform' = exp(xi) transform),
  /// from the point-to-plane normal equations at the solution, sigma^2 (sum_i J_i^T J_i)^-1
  /// with J_i = [(q_i x n_i)^T, n_i^T] over the inlier pairs (q_i the moved source point, n_i the
  /// target normal) and sigma^2 the inlier residuals' sum of squares over (pairs - 6). It treats
  /// the pairs' residuals as independent (downsampled points), so it says nothing of an error
  /// shared by all of them (a wrong correspondence basin, a deformed region). Empty when the
  /// region does not determine every direction (pose_covariance_note says which).
  std::optional<Mat6> pose_covariance;
  std::string pose_covariance_note;
};

/// The covariance above from the inlier pairs: moved source points q, target normals n and the
/// point-to-plane residuals. Empty (with `note` saying why) for fewer than 7 pairs or a region
/// that leaves a direction of motion undetermined (a plane, a sphere, a surface of revolution).
std::optional<Mat6> point_to_plane_pose_covariance(const Points& q, const Points& n, const Eigen::VectorXd& residuals,
                                                   std::string& note);

/// Aligns `source` (rows are points, e.g. the supine rigid region) to `target` (e.g. the
/// prone chest ring), starting from `initial`. Normals of both are estimated from
/// neighbours. Throws InputError for empty or NaN clouds.
IcpResult align_icp(const Points& source, const Points& target, const Rigid& initial, const IcpOptions& opt);

/// A fixed ICP target prepared once: points with known unit normals (e.g. samples of a
/// model surface) and their kd-tree or nearest-sample grid, so that aligning a stream of
/// clouds to it costs only the source's downsampling and the iterations.
class IcpTarget {
 public:
  /// With lookup_cell > 0, correspondences are found in constant time by a
  /// NearestSampleGrid of that cell size covering lookup_radius around the points (which
  /// must be at least the max_correspondence_distance of later alignments); otherwise by
  /// the kd-tree. Throws InputError when there are fewer than 6 points, the sizes differ,
  /// a value is not finite or a normal is not of unit length.
  IcpTarget(const Points& points, const Points& normals, double lookup_cell = 0, double lookup_radius = 0);
  ~IcpTarget();
  IcpTarget(IcpTarget&&) noexcept;
  IcpTarget& operator=(IcpTarget&&) noexcept;
  Eigen::Index size() const;
  /// The correspondence radius the grid covers [m]; 0 without a grid.
  double lookup_radius() const;

 private:
  friend IcpResult align_icp(const Points&, const IcpTarget&, const Rigid&, const IcpOptions&);
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// Aligns `source` (voxel-downsampled by opt.voxel_size; no normals needed) to a prepared
/// target by point-to-plane ICP with the target's normals. Only the fine pass
/// (max_correspondence_distance) runs. Throws InputError for an empty or NaN source.
IcpResult align_icp(const Points& source, const IcpTarget& target, const Rigid& initial, const IcpOptions& opt);

}  // namespace btr
