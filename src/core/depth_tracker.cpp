#include "breast_tumour_registration/core/depth_tracker.h"

#include <chrono>
#include <limits>

#include "breast_tumour_registration/core/errors.h"

namespace btr {

DepthTracker::DepthTracker(Points rigid_region, const Rigid& initial, const DepthTrackerOptions& opt)
    : rigid_(std::move(rigid_region)), guess_(initial), opt_(opt) {
  if (rigid_.rows() < 6) throw InputError("depth tracking needs a rigid region with at least 6 points");
  if ((opt_.roi_max - opt_.roi_min).minCoeff() <= 0) throw InputError("depth tracking: roi_max must exceed roi_min");
}

TrackingResult DepthTracker::process(Points& cloud, const Rigid& sensor_to_working) {
  using Clock = std::chrono::steady_clock;
  TrackingResult r;
  auto t0 = Clock::now();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  Points finite(cloud.rows(), 3);
  Eigen::Index k = 0;
  for (Eigen::Index i = 0; i < cloud.rows(); ++i) {
    if (!cloud.row(i).allFinite()) continue;
    const Vec3 p = sensor_to_working * Vec3(cloud.row(i).transpose());
    if ((p.array() < opt_.roi_min.array()).any() || (p.array() > opt_.roi_max.array()).any()) {
      cloud.row(i).setConstant(nan);
      continue;
    }
    cloud.row(i) = p.transpose();
    finite.row(k++) = p.transpose();
  }
  finite.conservativeResize(k, 3);
  r.points_in_roi = k;
  r.seconds_filter = std::chrono::duration<double>(Clock::now() - t0).count();
  if (k == 0) throw InputError("no finite point of the cloud lies inside the region of interest");

  t0 = Clock::now();
  IcpOptions icp;
  icp.voxel_size = opt_.voxel_size;
  icp.max_correspondence_distance = opt_.max_correspondence;
  icp.min_overlap = opt_.min_overlap;
  const bool locked = pose_.has_value();
  icp.max_iterations = locked ? opt_.max_iterations : opt_.capture_iterations;
  icp.coarse_correspondence_distance = locked ? 0.0 : opt_.capture_correspondence;
  r.icp = align_icp(rigid_, finite, guess_, icp);
  r.seconds_icp = std::chrono::duration<double>(Clock::now() - t0).count();
  r.accepted = r.icp.accepted;
  if (r.accepted) {
    pose_ = r.icp.transform;
    guess_ = r.icp.transform;
    ++consecutive_;
  } else {
    consecutive_ = 0;
  }
  return r;
}

}  // namespace btr
