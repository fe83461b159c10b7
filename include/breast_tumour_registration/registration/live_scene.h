// A live registration's scene: the prepared scene with its supine side replaced by the
// latest depth scan. What the ROS node's ~register service does with use_latest_cloud, as
// a core function (tested without ROS).
#pragma once

#include <optional>

#include "breast_tumour_registration/geometry/rigid_transform.h"
#include "breast_tumour_registration/io/scene.h"

namespace btr {

struct LiveScan {
  Points cloud;           ///< working frame [m]; organized (width * height rows, NaN = no data) or not (width 0)
  int width = 0, height = 0;
  Rigid supine_to_working = Rigid::Identity();  ///< the tracked alignment of the scene's supine frame
  /// How well that alignment is known (DepthTracker::pose_covariance: a motion of its inverse in
  /// the scene's frame); empty: held.
  std::optional<Mat6> pose_covariance;
};

struct LiveSceneOptions {
  double max_depth_edge = 0.01;  ///< [m] no triangle across a longer edge (depth discontinuities)
  bool use_landmarks = true;     ///< keep the scene's supine landmarks (moved into the working frame)
  /// An organized scan whose estimated depth noise (estimate_organized_noise) exceeds
  /// smoothing_min_noise [m] is smoothed in its image grid first (smooth_organized, Gaussian
  /// sigma in pixels; 0: never): the surface step projects onto it, and a depth camera's
  /// per-pixel noise otherwise keeps the skin sliding (BENCHMARKS.md, issue 10). A scan without
  /// measurable noise is left as it is: there the smoothing only costs accuracy.
  double smoothing_pixels = 2.0;
  double smoothing_min_noise = 2e-4;
};

struct LiveScene {
  Scene scene;                  ///< supine side in the working frame; automatic steps
  Rigid known_supine_to_model;  ///< for RegistrationOptions::known_supine_to_model: the tracked pose decides
  std::optional<Mat6> known_pose_covariance;  ///< for RegistrationOptions::known_pose_covariance (the scan's)
  double estimated_noise = 0;   ///< [m] an organized scan's estimated depth noise (0: not organized)
  bool smoothed = false;        ///< the scan was smoothed before triangulation
};

/// The scene to register against the scan: an organized cloud is triangulated (the surface
/// step projects onto it), an unorganized one is used as points (PCA normals); the scene's
/// supine landmarks (or none, without use_landmarks) and tumour ground truth are moved into
/// the working frame by the tracked alignment, and the steps are planned automatically from
/// what remains. InputError for a cloud that gives no surface or no finite point.
LiveScene live_scene(const Scene& prepared, const LiveScan& scan, const LiveSceneOptions& opt = {});

}  // namespace btr
