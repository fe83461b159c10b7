// Tracking of the prone model's rigid region (the chest skin around the breast) in a stream
// of depth clouds: each cloud is moved into the working frame, cropped to a region of
// interest and aligned by warm-started ICP. Used by the ROS node and by the tracking
// benchmark, so that the figures measure the node's own code path.
#pragma once

#include <optional>

#include "breast_tumour_registration/core/icp_alignment.h"

namespace btr {

struct DepthTrackerOptions {
  double voxel_size = 0.004;              ///< [m]
  int max_iterations = 10;                ///< per cloud, once locked on
  double max_correspondence = 0.01;       ///< [m]
  double capture_correspondence = 0.05;   ///< [m] wide first pass until the first success
  int capture_iterations = 40;
  Vec3 roi_min = Vec3::Constant(-1e9), roi_max = Vec3::Constant(1e9);  ///< working frame [m]
  double min_overlap = 0.2;
  /// Once locked on, only cloud points within about this distance of the rigid region (under
  /// the current pose) take part: the deforming breast skin would bias the alignment [m];
  /// <= 0 keeps every point.
  double region_band = 0.008;
};

struct TrackingResult {
  bool accepted = false;
  IcpResult icp;
  long points_in_roi = 0;
  long points_near_region = 0;  ///< after the rigid-region band filter (locked tracking)
  double seconds_filter = 0;  ///< transform and crop
  double seconds_icp = 0;     ///< downsampling, normals and ICP
};

/// Moves the finite points of `cloud` (sensor frame, NaN allowed, layout kept) into the
/// working frame in place, sets those outside [roi_min, roi_max] to NaN, and returns the
/// remaining finite points (working frame).
Points to_working_frame(Points& cloud, const Rigid& sensor_to_working, const Vec3& roi_min, const Vec3& roi_max);

/// The part of a rigid region farther than `margin` [m] from the breast surface `skin`:
/// the deforming breast bulges over the nearest part of the chest skin in a depth view, so
/// tracking on it would be biased. Throws InputError if fewer than 6 points remain.
Points rigid_region_clear_of(const Points& region, const SurfaceMesh& skin, double margin);

class DepthTracker {
 public:
  /// rigid_region: points of the model's rigid region in the model frame;
  /// initial: a guess of model -> working frame.
  DepthTracker(Points rigid_region, const Rigid& initial, const DepthTrackerOptions& opt);

  /// cloud: organized or not, in the sensor frame, NaN allowed; on return it holds the
  /// points in the working frame with those outside the ROI set to NaN (same layout).
  /// Throws InputError when no finite point is left inside the ROI.
  TrackingResult process(Points& cloud, const Rigid& sensor_to_working);

  /// The last accepted model -> working transform, if any.
  const std::optional<Rigid>& pose() const { return pose_; }
  /// Consecutive accepted clouds (0 after a rejection).
  int consecutive() const { return consecutive_; }

 private:
  bool near_region(const Vec3& model_point) const;
  Points rigid_;
  std::vector<long long> region_voxels_;  // sorted keys of the dilated rigid-region voxels
  Rigid guess_;
  DepthTrackerOptions opt_;
  std::optional<Rigid> pose_;
  int consecutive_ = 0;
};

}  // namespace btr
