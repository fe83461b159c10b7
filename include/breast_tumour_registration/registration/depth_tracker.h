// Tracking of the prone model's rigid region (the chest skin around the breast) in a stream
// of depth clouds: each cloud is moved into the working frame, cropped to a region of
// interest and to a band around the region, and aligned by warm-started point-to-plane ICP
// onto samples of the region prepared once (exact surface normals, kd-tree built once).
// Used by the ROS node and by the tracking benchmark, so that the figures measure the
// node's own code path.
#pragma once

#include <deque>
#include <optional>

#include "breast_tumour_registration/registration/icp_alignment.h"

namespace btr {

struct DepthTrackerOptions {
  double voxel_size = 0.002;              ///< [m] cloud downsampling once locked on; 0: none
  int max_iterations = 10;                ///< per cloud, once locked on
  double max_correspondence = 0.01;       ///< [m]
  double capture_correspondence = 0.05;   ///< [m] wide first pass until the first success
  int capture_iterations = 40;
  double capture_voxel_size = 0.004;      ///< [m] downsampling of region and cloud for the capture
  /// After a capture, the same cloud is aligned again this many times at refine_voxel_size
  /// with up to refine_iterations each (band filter renewed from the refined pose), so that
  /// the first pose is as accurate as the cloud allows.
  int refine_rounds = 2;
  double refine_voxel_size = 0.0;        ///< [m]; 0: every point
  int refine_iterations = 30;
  Vec3 roi_min = Vec3::Constant(-1e9), roi_max = Vec3::Constant(1e9);  ///< working frame [m]
  double min_overlap = 0.2;
  /// Only cloud points within about this distance of the rigid region (under the current
  /// pose) are aligned: the deforming breast skin would bias the alignment [m].
  double region_band = 0.008;
  /// [m] cell of the grid that finds ICP correspondences on the region in constant time;
  /// <= 0: kd-tree queries (a few microseconds each).
  double lookup_cell = 0.002;
  /// pose() is the mean of the last this many accepted poses (1: the latest alone): one
  /// cloud's pose scatters by its depth noise, the patient lies still. The window restarts
  /// when a new pose moves some rigid-region point more than motion_gate from the mean.
  int smoothing_clouds = 10;
  double motion_gate = 0.003;  ///< [m]
  /// A pose is accepted only if the aligned cloud reaches at least this fraction of the
  /// region's 1 cm cells: a cloud that touches a sliver of the region (patient leaving
  /// the view, region hidden) can fit it well in a wrong pose.
  double min_coverage = 0.3;
  /// After this many rejected clouds in a row the track is dropped and the next cloud is
  /// captured again (wide search from the last pose).
  int lost_after = 3;
};

struct TrackingResult {
  bool accepted = false;
  bool motion = false;     ///< the pose moved beyond the motion gate: smoothing restarted
  int smoothed_over = 0;   ///< accepted poses in the mean after this cloud
  bool captured = false;   ///< this cloud ran the capture (wide search) and refinement
  /// icp.transform: model -> working frame. icp.pose_covariance stays that of the last fit as
  /// align_icp gave it (a refinement: of working -> model, a motion in the model frame; a
  /// capture without refinement: of model -> working), for one cloud; the smoothed pose's is
  /// DepthTracker::pose_covariance().
  IcpResult icp;
  long points_in_roi = 0;
  long points_near_region = 0;  ///< after the rigid-region band filter
  double region_coverage = 0;   ///< fraction of the region's 1 cm cells the aligned cloud reaches
  double seconds_filter = 0;  ///< transform, crop and band filter
  double seconds_icp = 0;     ///< downsampling and ICP (capture and refinement included)
};

/// Moves the finite points of `cloud` (sensor frame, NaN allowed, layout kept) into the
/// working frame in place, sets those outside [roi_min, roi_max] to NaN, and returns the
/// remaining finite points (working frame).
Points to_working_frame(Points& cloud, const Rigid& sensor_to_working, const Vec3& roi_min, const Vec3& roi_max);

/// Points on a rigid surface with the unit normals of their triangles (model frame).
struct SurfaceSamples {
  Points points;
  Points normals;
};

/// Samples the triangles of `region` about every `spacing` [m] and keeps those farther
/// than `margin` [m] from the breast surface `skin`: the deforming breast bulges over the
/// nearest part of the chest skin in a depth view, so tracking on it would be biased.
/// Throws InputError if fewer than 6 samples remain or an argument is out of range.
SurfaceSamples rigid_region_samples(const SurfaceMesh& region, const SurfaceMesh& skin, double margin, double spacing);

class DepthTracker {
 public:
  /// region: samples of the model's rigid region (model frame); initial: a guess of the
  /// model -> working frame transform. The ICP target (the region with its kd-tree) is
  /// prepared here once.
  DepthTracker(SurfaceSamples region, const Rigid& initial, const DepthTrackerOptions& opt);

  /// cloud: organized or not, in the sensor frame, NaN allowed; on return it holds the
  /// points in the working frame with those outside the ROI set to NaN (same layout).
  /// Until the first accepted cloud, the region is captured by a wide search from the
  /// guess and refined; afterwards each cloud is aligned warm-started from the last pose.
  /// Throws InputError when no finite point is left inside the ROI.
  TrackingResult process(Points& cloud, const Rigid& sensor_to_working);

  /// The model -> working transform: the mean of the recent accepted poses (see
  /// DepthTrackerOptions::smoothing_clouds), if any cloud was accepted since the last
  /// capture.
  const std::optional<Rigid>& pose() const { return pose_; }
  /// The pose from the last accepted cloud alone.
  const std::optional<Rigid>& latest_pose() const { return latest_; }
  /// How well pose() is known: the covariance of a small motion xi = (omega [rad], tau [m]) of
  /// its inverse (working -> model), applied in the model frame, as IcpResult::pose_covariance
  /// has it (RegistrationOptions::known_pose_covariance takes it so). The refinement fits'
  /// covariances over the smoothing window, averaged and divided by its size: the clouds' noise
  /// taken as independent from one cloud to the next. Empty when a pose in the window has none
  /// (a capture without refinement, a region that leaves a motion undetermined).
  std::optional<Mat6> pose_covariance() const;
  /// Consecutive accepted clouds (0 after a rejection or a new capture).
  int consecutive() const { return consecutive_; }

 private:
  Points near_region(const Points& finite, const Rigid& model_to_working) const;
  double coverage(const Points& near, const Rigid& model_to_working) const;
  /// Adds an accepted pose (and its fit's covariance, if known) to the smoothing window;
  /// returns true if it restarted it.
  bool smooth(const Rigid& latest, const std::optional<Mat6>& covariance);
  SurfaceSamples region_;
  Points corners_;  // corners of the region's bounding box (motion gate)
  struct WindowPose {
    Rigid pose;
    std::optional<Mat6> covariance;  // of its fit, if known
  };
  std::deque<WindowPose> window_;
  std::optional<Rigid> latest_;
  IcpTarget target_;
  std::vector<long long> region_voxels_;  // sorted keys of the dilated rigid-region voxels
  std::vector<long long> region_cells_;   // sorted keys of the region's 1 cm cells (coverage)
  Rigid guess_;
  DepthTrackerOptions opt_;
  std::optional<Rigid> pose_;
  int consecutive_ = 0;
  int rejected_ = 0;  // rejected clouds in a row
};

}  // namespace btr
