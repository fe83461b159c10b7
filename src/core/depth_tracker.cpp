#include "breast_tumour_registration/core/depth_tracker.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>

#include "breast_tumour_registration/core/errors.h"
#include "breast_tumour_registration/core/metrics.h"

namespace btr {

namespace {
long long voxel_key(const Vec3& p, double h) {
  const long long x = static_cast<long long>(std::floor(p.x() / h)) + (1 << 20);
  const long long y = static_cast<long long>(std::floor(p.y() / h)) + (1 << 20);
  const long long z = static_cast<long long>(std::floor(p.z() / h)) + (1 << 20);
  return (x << 42) | (y << 21) | z;
}
}  // namespace

DepthTracker::DepthTracker(Points rigid_region, const Rigid& initial, const DepthTrackerOptions& opt)
    : rigid_(std::move(rigid_region)), guess_(initial), opt_(opt) {
  if (rigid_.rows() < 6) throw InputError("depth tracking needs a rigid region with at least 6 points");
  if ((opt_.roi_max - opt_.roi_min).minCoeff() <= 0) throw InputError("depth tracking: roi_max must exceed roi_min");
  if (opt_.region_band > 0) {
    // Voxels of the region's points, densified along its extent, dilated by one voxel.
    const double h = opt_.region_band;
    for (Eigen::Index i = 0; i < rigid_.rows(); ++i)
      for (int dx = -1; dx <= 1; ++dx)
        for (int dy = -1; dy <= 1; ++dy)
          for (int dz = -1; dz <= 1; ++dz)
            region_voxels_.push_back(voxel_key(Vec3(rigid_.row(i).transpose()) + h * Vec3(dx, dy, dz), h));
    std::sort(region_voxels_.begin(), region_voxels_.end());
    region_voxels_.erase(std::unique(region_voxels_.begin(), region_voxels_.end()), region_voxels_.end());
  }
}

Points to_working_frame(Points& cloud, const Rigid& sensor_to_working, const Vec3& roi_min, const Vec3& roi_max) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  Points finite(cloud.rows(), 3);
  Eigen::Index k = 0;
  for (Eigen::Index i = 0; i < cloud.rows(); ++i) {
    if (!cloud.row(i).allFinite()) continue;
    const Vec3 p = sensor_to_working * Vec3(cloud.row(i).transpose());
    if ((p.array() < roi_min.array()).any() || (p.array() > roi_max.array()).any()) {
      cloud.row(i).setConstant(nan);
      continue;
    }
    cloud.row(i) = p.transpose();
    finite.row(k++) = p.transpose();
  }
  finite.conservativeResize(k, 3);
  return finite;
}

Points rigid_region_clear_of(const Points& region, const SurfaceMesh& skin, double margin) {
  const std::vector<double> d = point_to_surface_distances(region, skin);
  Points out(region.rows(), 3);
  Eigen::Index k = 0;
  for (Eigen::Index i = 0; i < region.rows(); ++i)
    if (d[i] > margin) out.row(k++) = region.row(i);
  out.conservativeResize(k, 3);
  if (k < 6)
    throw InputError("the rigid region has fewer than 6 points farther than " + std::to_string(margin * 1e3) +
                     " mm from the breast; give a wider chest_ring");
  return out;
}

bool DepthTracker::near_region(const Vec3& p) const {
  return std::binary_search(region_voxels_.begin(), region_voxels_.end(), voxel_key(p, opt_.region_band));
}

TrackingResult DepthTracker::process(Points& cloud, const Rigid& sensor_to_working) {
  using Clock = std::chrono::steady_clock;
  TrackingResult r;
  auto t0 = Clock::now();
  Points finite = to_working_frame(cloud, sensor_to_working, opt_.roi_min, opt_.roi_max);
  const Eigen::Index k = finite.rows();
  r.points_in_roi = k;
  if (pose_ && opt_.region_band > 0) {
    const Rigid to_model = guess_.inverse();
    Eigen::Index m = 0;
    for (Eigen::Index i = 0; i < finite.rows(); ++i)
      if (near_region(to_model * Vec3(finite.row(i).transpose()))) finite.row(m++) = finite.row(i);
    finite.conservativeResize(m, 3);
  }
  r.points_near_region = finite.rows();
  r.seconds_filter = std::chrono::duration<double>(Clock::now() - t0).count();
  if (k == 0) throw InputError("no finite point of the cloud lies inside the region of interest");
  if (finite.rows() < 6) {
    consecutive_ = 0;
    r.icp.message = "too few cloud points near the rigid region under the tracked pose (lost track?)";
    pose_.reset();  // fall back to capture on the next cloud
    return r;
  }

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
