#include "breast_tumour_registration/registration/live_scene.h"

#include <cmath>
#include <limits>

#include "breast_tumour_registration/base/errors.h"
#include "breast_tumour_registration/geometry/organized_cloud.h"

namespace btr {

LiveScene live_scene(const Scene& prepared, const LiveScan& scan, const LiveSceneOptions& opt) {
  LiveScene live{prepared, scan.supine_to_working.inverse(), scan.pose_covariance};
  Scene& s = live.scene;
  if (scan.width > 0) {
    const double noise = is_organized(scan.cloud, scan.width, scan.height) ? estimate_organized_noise(scan.cloud, scan.width, scan.height, opt.max_depth_edge)
                                   : std::numeric_limits<double>::quiet_NaN();  // triangulate_organized says why
    live.estimated_noise = std::isfinite(noise) ? noise : 0.0;
    live.smoothed = opt.smoothing_pixels > 0 && live.estimated_noise > opt.smoothing_min_noise;
    s.supine_surface = triangulate_organized(
        live.smoothed ? smooth_organized(scan.cloud, scan.width, scan.height, opt.smoothing_pixels, opt.max_depth_edge) : scan.cloud,
        scan.width, scan.height, opt.max_depth_edge);
    s.supine_cloud.reset();
  } else {
    Points finite = finite_points(scan.cloud);
    if (finite.rows() == 0) throw InputError("the depth cloud has no finite point");
    s.supine_surface.reset();
    s.supine_cloud = std::move(finite);
  }
  // The scan replaces the supine data; what stays of it (landmarks, ground truth) was given in
  // the scene's supine frame and moves into the working frame with the tracked alignment.
  s.supine_rigid.reset();
  if (opt.use_landmarks && s.landmark_supine.rows()) {
    s.landmark_supine = transform_points(scan.supine_to_working, s.landmark_supine);
  } else {
    s.landmark_anchors.clear();
    s.landmark_supine.resize(0, 3);
  }
  for (auto& t : s.tumours)
    if (t.supine_ground_truth) t.supine_ground_truth = transform_surface(scan.supine_to_working, *t.supine_ground_truth);
  s.steps.clear();
  return live;
}

}  // namespace btr
