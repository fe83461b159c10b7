#include "breast_tumour_registration/registration/depth_tracker.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>

#include "breast_tumour_registration/base/errors.h"
#include "breast_tumour_registration/geometry/metrics.h"

namespace btr {

namespace {
long long voxel_key(const Vec3& p, double h) {
  const long long x = static_cast<long long>(std::floor(p.x() / h)) + (1 << 20);
  const long long y = static_cast<long long>(std::floor(p.y() / h)) + (1 << 20);
  const long long z = static_cast<long long>(std::floor(p.z() / h)) + (1 << 20);
  return (x << 42) | (y << 21) | z;
}
constexpr double kCoverageCell = 0.01;  // [m]

void sort_unique(std::vector<long long>& keys) {
  std::sort(keys.begin(), keys.end());
  keys.erase(std::unique(keys.begin(), keys.end()), keys.end());
}

/// The options, after checking every one (before anything is built from them).
const DepthTrackerOptions& checked(const DepthTrackerOptions& o) {
  if ((o.roi_max - o.roi_min).minCoeff() <= 0) throw InputError("depth tracking: roi_max must exceed roi_min");
  if (!(o.voxel_size >= 0) || !(o.refine_voxel_size >= 0) || !(o.capture_voxel_size >= 0) || o.max_iterations < 1 ||
      o.refine_rounds < 0 || o.refine_iterations < 1 || o.capture_iterations < 1 || !(o.max_correspondence > 0))
    throw InputError("depth tracking: voxel sizes must be >= 0, iteration counts >= 1 and max_correspondence > 0");
  if (o.smoothing_clouds < 1 || !(o.motion_gate > 0))
    throw InputError("depth tracking: smoothing_clouds must be >= 1 and motion_gate > 0");
  if (!(o.min_coverage >= 0 && o.min_coverage <= 1) || o.lost_after < 1)
    throw InputError("depth tracking: min_coverage must be in [0, 1] and lost_after >= 1");
  return o;
}
}  // namespace

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

SurfaceSamples rigid_region_samples(const SurfaceMesh& region, const SurfaceMesh& skin, double margin, double spacing) {
  if (!(spacing > 0) || !(margin >= 0)) throw InputError("rigid region sampling: spacing must be positive and margin >= 0");
  if (region.F.rows() == 0) throw InputError("the rigid region (chest_ring) has no triangles");
  // Each triangle is cut into n x n similar triangles (n from its longest edge) and
  // sampled at their centroids, each carrying the triangle's normal.
  std::vector<Vec3> pts, nrm;
  for (Eigen::Index f = 0; f < region.F.rows(); ++f) {
    const Vec3 a = region.V.row(region.F(f, 0)), b = region.V.row(region.F(f, 1)), c = region.V.row(region.F(f, 2));
    const Vec3 cross = (b - a).cross(c - a);
    if (!(cross.norm() > 0)) continue;  // degenerate triangle: no normal
    const Vec3 n = cross.normalized();
    const double longest = std::max({(b - a).norm(), (c - b).norm(), (a - c).norm()});
    const int k = std::max(1, static_cast<int>(std::ceil(longest / spacing)));
    for (int i = 0; i < k; ++i)
      for (int j = 0; i + j < k; ++j) {
        for (const double o : {1.0 / 3.0, 2.0 / 3.0}) {
          if (o > 0.5 && i + j >= k - 1) continue;  // the downward triangles exist only inside
          const double u = (i + o) / k, v = (j + o) / k;
          pts.push_back(a + u * (b - a) + v * (c - a));
          nrm.push_back(n);
        }
      }
  }
  Points P(pts.size(), 3);
  for (size_t i = 0; i < pts.size(); ++i) P.row(i) = pts[i].transpose();
  const std::vector<double> d = point_to_surface_distances(P, skin);
  SurfaceSamples out;
  out.points.resize(P.rows(), 3);
  out.normals.resize(P.rows(), 3);
  Eigen::Index m = 0;
  for (Eigen::Index i = 0; i < P.rows(); ++i)
    if (d[i] > margin) {
      out.points.row(m) = P.row(i);
      out.normals.row(m++) = nrm[i].transpose();
    }
  out.points.conservativeResize(m, 3);
  out.normals.conservativeResize(m, 3);
  if (m < 6)
    throw InputError("the rigid region has fewer than 6 points farther than " + std::to_string(margin * 1e3) +
                     " mm from the breast; give a wider chest_ring");
  return out;
}

DepthTracker::DepthTracker(SurfaceSamples region, const Rigid& initial, const DepthTrackerOptions& opt)
    : region_(std::move(region)),
      target_(region_.points, region_.normals, checked(opt).lookup_cell, opt.max_correspondence + std::max(0.0, opt.lookup_cell)),
      guess_(initial),
      opt_(opt) {
  const Vec3 lo = region_.points.colwise().minCoeff().transpose(), hi = region_.points.colwise().maxCoeff().transpose();
  corners_.resize(8, 3);
  for (int c = 0; c < 8; ++c)
    corners_.row(c) << (c & 1 ? hi : lo).x(), (c & 2 ? hi : lo).y(), (c & 4 ? hi : lo).z();
  for (Eigen::Index i = 0; i < region_.points.rows(); ++i)
    region_cells_.push_back(voxel_key(region_.points.row(i).transpose(), kCoverageCell));
  sort_unique(region_cells_);
  if (opt_.region_band > 0) {
    // Voxels of the region's samples, dilated by one voxel.
    const double h = opt_.region_band;
    for (Eigen::Index i = 0; i < region_.points.rows(); ++i)
      for (int dx = -1; dx <= 1; ++dx)
        for (int dy = -1; dy <= 1; ++dy)
          for (int dz = -1; dz <= 1; ++dz)
            region_voxels_.push_back(voxel_key(Vec3(region_.points.row(i).transpose()) + h * Vec3(dx, dy, dz), h));
    sort_unique(region_voxels_);
  }
}

Points DepthTracker::near_region(const Points& finite, const Rigid& model_to_working) const {
  if (opt_.region_band <= 0) return finite;
  const Rigid to_model = model_to_working.inverse();
  Points out(finite.rows(), 3);
  Eigen::Index m = 0;
  for (Eigen::Index i = 0; i < finite.rows(); ++i) {
    const Vec3 p = to_model * Vec3(finite.row(i).transpose());
    if (std::binary_search(region_voxels_.begin(), region_voxels_.end(), voxel_key(p, opt_.region_band)))
      out.row(m++) = finite.row(i);
  }
  out.conservativeResize(m, 3);
  return out;
}

double DepthTracker::coverage(const Points& near, const Rigid& model_to_working) const {
  const Rigid to_model = model_to_working.inverse();
  std::vector<long long> hit;
  for (Eigen::Index i = 0; i < near.rows(); i += 4) {  // every 4th point: cells are 1 cm wide
    const long long k = voxel_key(to_model * Vec3(near.row(i).transpose()), kCoverageCell);
    if (std::binary_search(region_cells_.begin(), region_cells_.end(), k)) hit.push_back(k);
  }
  sort_unique(hit);
  return static_cast<double>(hit.size()) / region_cells_.size();
}

std::optional<Mat6> DepthTracker::pose_covariance() const {
  if (!pose_ || window_.empty()) return std::nullopt;
  Mat6 sum = Mat6::Zero();
  for (const WindowPose& w : window_) {
    if (!w.covariance) return std::nullopt;
    sum += *w.covariance;
  }
  const double n = static_cast<double>(window_.size());
  return Mat6(sum / (n * n));  // the mean of n independent poses
}

bool DepthTracker::smooth(const Rigid& latest, const std::optional<Mat6>& covariance) {
  // A rigid motion's largest displacement over the region is at a corner of its hull, so
  // the bounding-box corners bound it from above.
  const bool restart = pose_ && max_displacement(latest, *pose_, corners_) > opt_.motion_gate;
  if (restart) window_.clear();
  window_.push_back({latest, covariance});
  while (static_cast<int>(window_.size()) > opt_.smoothing_clouds) window_.pop_front();
  // Mean of the window: translations averaged, rotations by the normalized mean of
  // sign-aligned quaternions (accurate for the small spread of tracking noise).
  const Eigen::Quaterniond q0(window_.front().pose.linear());
  Eigen::Vector4d q = Eigen::Vector4d::Zero();
  Vec3 t = Vec3::Zero();
  for (const WindowPose& w : window_) {
    const Rigid& T = w.pose;
    const Eigen::Quaterniond qi(T.linear());
    q += (qi.dot(q0) < 0 ? -1.0 : 1.0) * qi.coeffs();
    t += T.translation();
  }
  Rigid mean = Rigid::Identity();
  mean.linear() = Eigen::Quaterniond(q.normalized()).toRotationMatrix();
  mean.translation() = t / static_cast<double>(window_.size());
  pose_ = mean;
  return restart;
}

TrackingResult DepthTracker::process(Points& cloud, const Rigid& sensor_to_working) {
  using Clock = std::chrono::steady_clock;
  const auto seconds_since = [](Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); };
  TrackingResult r;
  auto t0 = Clock::now();
  const Points finite = to_working_frame(cloud, sensor_to_working, opt_.roi_min, opt_.roi_max);
  r.points_in_roi = finite.rows();
  if (finite.rows() == 0) throw InputError("no finite point of the cloud lies inside the region of interest");
  r.seconds_filter = seconds_since(t0);

  // One fine alignment of the cloud's points near the region onto the prepared region;
  // false when too few points are near it.
  IcpOptions fine;
  fine.max_correspondence_distance = opt_.max_correspondence;
  fine.min_overlap = opt_.min_overlap;
  Rigid pose = guess_;
  bool refined = false;  // r.icp is a refinement (working -> model), not the capture
  const auto align_near = [&](double voxel, int iterations) {
    const auto tb = Clock::now();
    const Points near = near_region(finite, pose);
    r.points_near_region = near.rows();
    r.seconds_filter += seconds_since(tb);
    if (near.rows() < 6) {
      r.icp = IcpResult{};
      r.icp.message = "too few cloud points near the rigid region under the tracked pose (lost track?)";
      return false;
    }
    const auto ti = Clock::now();
    fine.voxel_size = voxel;
    fine.max_iterations = iterations;
    r.icp = align_icp(near, target_, pose.inverse(), fine);
    refined = true;
    r.icp.transform = r.icp.transform.inverse();  // working -> model, reported as model -> working
    pose = r.icp.transform;
    r.region_coverage = coverage(near, pose);
    if (r.icp.accepted && r.region_coverage < opt_.min_coverage) {
      r.icp.accepted = false;
      r.icp.message = "the cloud reaches only " + std::to_string(static_cast<int>(100 * r.region_coverage)) +
                      " % of the rigid region (at least " + std::to_string(static_cast<int>(100 * opt_.min_coverage)) +
                      " % needed): region hidden or out of view?";
    }
    r.seconds_icp += seconds_since(ti);
    return true;
  };

  bool ok = false;
  if (latest_) {
    ok = align_near(opt_.voxel_size, opt_.max_iterations) && r.icp.accepted;
  } else {
    // Capture: the region onto the whole cloud with a wide radius. In this direction every
    // region point has its partner in the cloud, so the breast does not pull it away.
    r.captured = true;
    const auto ti = Clock::now();
    IcpOptions capture;
    capture.voxel_size = opt_.capture_voxel_size;
    capture.max_correspondence_distance = opt_.max_correspondence;
    capture.coarse_correspondence_distance = opt_.capture_correspondence;
    capture.max_iterations = opt_.capture_iterations;
    capture.min_overlap = opt_.min_overlap;
    r.icp = align_icp(region_.points, finite, guess_, capture);
    r.seconds_icp += seconds_since(ti);
    ok = r.icp.accepted;
    if (ok) {
      pose = r.icp.transform;
      for (int round = 0; ok && round < opt_.refine_rounds; ++round)
        ok = align_near(opt_.refine_voxel_size, opt_.refine_iterations) && r.icp.accepted;
    }
  }
  r.accepted = ok;
  if (ok) {
    if (r.captured) window_.clear();
    r.motion = smooth(pose, refined ? r.icp.pose_covariance : std::nullopt);
    r.smoothed_over = static_cast<int>(window_.size());
    latest_ = pose;
    guess_ = pose;
    consecutive_ = r.captured ? 1 : consecutive_ + 1;
    rejected_ = 0;
  } else {
    consecutive_ = 0;
    ++rejected_;
    if (latest_ && (r.points_near_region < 6 || rejected_ >= opt_.lost_after)) {  // lost: capture again
      pose_.reset();
      latest_.reset();
      window_.clear();
    }
  }
  return r;
}

}  // namespace btr
