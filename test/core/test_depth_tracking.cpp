// Depth tracking of the rigid region: the constant-time correspondence grid, ICP onto a
// prepared target, and the tracker on rendered noisy depth clouds (capture from a large
// offset, smoothing, following a moving patient, losing and recapturing the region).
#include <algorithm>
#include <random>

#include "breast_tumour_registration/base/errors.h"
#include "breast_tumour_registration/geometry/metrics.h"
#include "breast_tumour_registration/geometry/nearest_sample_grid.h"
#include "breast_tumour_registration/geometry/shapes.h"
#include "breast_tumour_registration/registration/depth_tracker.h"
#include "breast_tumour_registration/simulation/depth_camera.h"
#include "test_util.h"

using namespace btr;
using btr::test::expect_throw_with;
using btr::test::make_rigid;

namespace {


// A breast dome on its chest ring, seen by a 320 x 240 depth camera with 1 mm noise.
struct TrackingScene {
  const double a = 0.0745;
  SurfaceMesh ring = make_chest_ring(a, a, 0.04, 144);
  SurfaceMesh dome = make_half_ellipsoid(a, a, 0.05, 16);
  SurfaceSamples region = rigid_region_samples(ring, dome, 0.015, 0.002);
  PinholeCamera cam;
  Rigid camera_to_world;
  TrackingScene() {
    cam.width = 320;
    cam.height = 240;
    cam.fx = cam.fy = 262.5;
    cam.cx = 159.5;
    cam.cy = 119.5;
  }
  // Noisy clouds (camera frame) of the patient at `model_to_world`.
  std::vector<Points> clouds(const Rigid& model_to_world, int n, unsigned seed) {
    camera_to_world = look_at(model_to_world * Vec3(0.0, -0.12, 0.45), model_to_world * Vec3(0.0, 0.0, 0.02),
                              model_to_world.linear() * Vec3(0, 1, 0));
    const SurfaceMesh r = transform_surface(model_to_world, ring), d = transform_surface(model_to_world, dome);
    const Points clean = render_depth({&r, &d}, cam, camera_to_world);
    std::mt19937 rng(seed);
    std::vector<Points> out(n, clean);
    for (auto& c : out) add_depth_noise(c, 1e-3, rng);
    return out;
  }
  // Largest displacement of a rigid-region sample between two poses [m].
  double region_error(const Rigid& A, const Rigid& B) const { return max_displacement(A, B, region.points); }
};

}  // namespace

TEST(NearestSampleGrid, AnswersWithinACellOfTheTrueNearestSample) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-0.05, 0.05);
  Points S(500, 3);
  for (int i = 0; i < S.size(); ++i) S.data()[i] = u(rng);
  const double cell = 0.002, radius = 0.01;
  const NearestSampleGrid grid(S, cell, radius);
  int answered = 0;
  for (int k = 0; k < 2000; ++k) {
    const Vec3 q(1.3 * u(rng), 1.3 * u(rng), 1.3 * u(rng));
    double best = 1e9;
    for (Eigen::Index i = 0; i < S.rows(); ++i) best = std::min(best, (S.row(i).transpose() - q).norm());
    const int j = grid.nearest(q);
    if (j >= 0) {
      ++answered;
      EXPECT_LE((S.row(j).transpose() - q).norm(), best + cell * std::sqrt(3.0) + 1e-12);
    } else {
      EXPECT_GT(best, radius - cell * std::sqrt(3.0) / 2);  // "none" only when no sample is near
    }
  }
  EXPECT_GT(answered, 100);
  EXPECT_EQ(grid.nearest(Vec3(1, 1, 1)), -1);
  EXPECT_EQ(grid.nearest(Vec3(std::nan(""), 0, 0)), -1);
  expect_throw_with<InputError>([] { NearestSampleGrid(Points(0, 3), 0.002, 0.01); }, "no samples");
  expect_throw_with<InputError>([&] { NearestSampleGrid(S, 0.0, 0.01); }, "must be positive");
  expect_throw_with<InputError>([&] { NearestSampleGrid(S, 1e-5, 0.01); }, "cells");
  Points bad = S;
  bad(3, 1) = std::nan("");
  expect_throw_with<InputError>([&] { NearestSampleGrid(bad, 0.002, 0.01); }, "finite");
}

TEST(IcpTarget, GridAndKdTreeAgreeAndBadTargetsAreRefused) {
  TrackingScene s;
  const Rigid T = make_rigid(Vec3(2, -1.5, 3), Vec3(0.003, -0.002, 0.002));  // working -> model
  const Points source = transform_points(T.inverse(), s.region.points);
  IcpOptions o;
  o.voxel_size = 0;
  o.max_iterations = 30;
  const IcpTarget tree(s.region.points, s.region.normals), grid(s.region.points, s.region.normals, 0.002, 0.012);
  const IcpResult a = align_icp(source, tree, Rigid::Identity(), o), b = align_icp(source, grid, Rigid::Identity(), o);
  ASSERT_TRUE(a.accepted) << a.message;
  ASSERT_TRUE(b.accepted) << b.message;
  EXPECT_LT(s.region_error(a.transform, T), 1e-4);
  EXPECT_LT(s.region_error(b.transform, T), 1e-4);
  EXPECT_DOUBLE_EQ(grid.lookup_radius(), 0.012);
  o.max_correspondence_distance = 0.02;
  expect_throw_with<InputError>([&] { align_icp(source, grid, Rigid::Identity(), o); }, "exceeds the radius");
  expect_throw_with<InputError>([&] { IcpTarget(s.region.points.topRows(5), s.region.normals.topRows(5)); }, "at least 6");
  expect_throw_with<InputError>([&] { IcpTarget(s.region.points, 2 * s.region.normals); }, "unit length");
  expect_throw_with<InputError>([&] { IcpTarget(s.region.points, s.region.normals.topRows(7)); }, "one normal per point");
}

TEST(RigidRegionSamples, KeepOnlyTheChestSkinClearOfTheBreast) {
  TrackingScene s;
  const std::vector<double> d = point_to_surface_distances(s.region.points, s.dome);
  EXPECT_GT(*std::min_element(d.begin(), d.end()), 0.015);
  EXPECT_GT(s.region.points.rows(), 1000);
  for (Eigen::Index i = 0; i < s.region.normals.rows(); ++i) EXPECT_NEAR(s.region.normals.row(i).norm(), 1.0, 1e-12);
  expect_throw_with<InputError>([&] { rigid_region_samples(s.ring, s.dome, 0.1, 0.002); }, "give a wider chest_ring");
  expect_throw_with<InputError>([&] { rigid_region_samples(s.ring, s.dome, 0.015, 0.0); }, "spacing");
}

TEST(DepthTracker, CapturesFromALargeOffsetAndSmoothsToSubMillimetre) {
  TrackingScene s;
  const Rigid truth = make_rigid(Vec3(0, 0, 20), Vec3(0.1, -0.05, 0.75));
  std::vector<Points> clouds = s.clouds(truth, 12, 1);
  DepthTrackerOptions o;
  DepthTracker tracker(s.region, truth * make_rigid(Vec3(0, 0, 15), Vec3(0.01, 0, 0)), o);  // 15 deg and 10 mm off
  TrackingResult r = tracker.process(clouds[0], s.camera_to_world);
  ASSERT_TRUE(r.accepted) << r.icp.message;
  EXPECT_TRUE(r.captured);
  EXPECT_LT(s.region_error(*tracker.pose(), truth), 0.0015);  // one cloud with 1 mm noise
  std::vector<double> raw;
  for (int i = 1; i < 12; ++i) {
    r = tracker.process(clouds[i], s.camera_to_world);
    ASSERT_TRUE(r.accepted) << r.icp.message;
    EXPECT_FALSE(r.captured);
    EXPECT_FALSE(r.motion);
    raw.push_back(s.region_error(*tracker.latest_pose(), truth));
  }
  EXPECT_EQ(r.smoothed_over, 10);
  EXPECT_EQ(tracker.consecutive(), 12);
  std::sort(raw.begin(), raw.end());
  const double smoothed = s.region_error(*tracker.pose(), truth);
  EXPECT_LT(smoothed, 0.0005);
  EXPECT_LT(smoothed, raw[raw.size() / 2]);  // the mean beats a typical single cloud
}

// The tracked pose's covariance (what the registration takes as the rigid pose's uncertainty):
// per cloud (a window of one) the pose errors' mean squared Mahalanobis distance under it must be
// near 6 (chi-square, 6 dof); the window's mean is known better by the window's size.
TEST(DepthTracker, ThePoseCovarianceMatchesThePoseErrorsOverNoisyClouds) {
  TrackingScene s;
  const Rigid truth = make_rigid(Vec3(0, 0, 20), Vec3(0.1, -0.05, 0.75));  // model -> working
  const int n = 30;
  std::vector<Points> clouds = s.clouds(truth, n, 5);
  DepthTrackerOptions o;
  o.smoothing_clouds = 1;
  DepthTracker tracker(s.region, truth * make_rigid(Vec3(0, 0, 2), Vec3(0.003, 0, 0)), o);
  double mahalanobis = 0;
  int used = 0;
  for (int i = 0; i < n; ++i) {
    const TrackingResult r = tracker.process(clouds[i], s.camera_to_world);
    ASSERT_TRUE(r.accepted) << r.icp.message;
    const auto cov = tracker.pose_covariance();
    ASSERT_TRUE(cov.has_value()) << r.icp.pose_covariance_note;
    if (i == 0) continue;  // the capture's pose
    const Rigid err = tracker.pose()->inverse() * truth;  // exp(xi) of working -> model: (T' T^-1), T = truth^-1
    const Vec6 xi = motion_of(err);
    mahalanobis += xi.dot(cov->ldlt().solve(xi));
    ++used;
  }
  mahalanobis /= used;
  std::printf("tracked pose: mean Mahalanobis %.2f over %d clouds (chi-square 6 dof: 6)\n", mahalanobis, used);
  EXPECT_GT(mahalanobis, 2.0);
  EXPECT_LT(mahalanobis, 18.0);
  // A window of ten: the mean of ten independent clouds' poses.
  DepthTrackerOptions w;
  DepthTracker windowed(s.region, truth, w);
  std::vector<Points> more = s.clouds(truth, 11, 6);
  // The trace, not a std::optional<Mat6>: GCC 12 warns that the optional's Eigen storage
  // may be used uninitialized (a false positive of -Wmaybe-uninitialized).
  double single_trace = -1;  // a window of one: the capture, refined
  for (int i = 0; i < 11; ++i) {
    ASSERT_TRUE(windowed.process(more[i], s.camera_to_world).accepted);
    if (i == 0 && windowed.pose_covariance()) single_trace = windowed.pose_covariance()->trace();
  }
  ASSERT_TRUE(single_trace > 0 && windowed.pose_covariance());
  EXPECT_LT(windowed.pose_covariance()->trace(), 0.3 * single_trace);
}

TEST(DepthTracker, FollowsAMovingPatientAndRecapturesWhenLost) {
  TrackingScene s;
  const Rigid truth = make_rigid(Vec3(0, 0, 20), Vec3(0.1, -0.05, 0.75));
  DepthTrackerOptions o;
  DepthTracker tracker(s.region, truth, o);
  for (Points& c : s.clouds(truth, 4, 2)) ASSERT_TRUE(tracker.process(c, s.camera_to_world).accepted);
  // The patient shifts by 4 mm and turns by 1 deg (the camera stays where it was).
  const Rigid camera = s.camera_to_world;
  const Rigid moved = make_rigid(Vec3(0, 0, 21), Vec3(0.104, -0.05, 0.75));
  std::vector<Points> after = s.clouds(moved, 4, 3);
  bool motion = false;
  for (Points& c : after) {
    // Re-express each cloud in the fixed camera's frame.
    for (Eigen::Index i = 0; i < c.rows(); ++i)
      if (c.row(i).allFinite()) c.row(i) = (camera.inverse() * (s.camera_to_world * Vec3(c.row(i).transpose()))).transpose();
    const TrackingResult r = tracker.process(c, camera);
    ASSERT_TRUE(r.accepted) << r.icp.message;
    motion = motion || r.motion;
  }
  EXPECT_TRUE(motion);
  EXPECT_LT(s.region_error(*tracker.pose(), moved), 0.001);
  // Far away: the cloud reaches a sliver of the region under the tracked pose, where a
  // nearly flat ring could fit well in a wrong pose. It is rejected for its coverage, and
  // after lost_after rejections in a row the track is dropped and the next cloud recaptures.
  std::vector<Points> far = s.clouds(make_rigid(Vec3(0, 0, 20), Vec3(0.3, -0.05, 0.75)), o.lost_after, 4);
  for (int i = 0; i < o.lost_after; ++i) {
    EXPECT_TRUE(tracker.pose().has_value());
    const TrackingResult lost = tracker.process(far[i], s.camera_to_world);
    EXPECT_FALSE(lost.accepted);
    EXPECT_LT(lost.region_coverage, o.min_coverage);
    EXPECT_NE(lost.icp.message.find("of the rigid region"), std::string::npos) << lost.icp.message;
  }
  EXPECT_FALSE(tracker.pose().has_value());
  Points back = s.clouds(truth, 1, 5)[0];
  const TrackingResult again = tracker.process(back, s.camera_to_world);
  EXPECT_TRUE(again.captured);
  EXPECT_TRUE(again.accepted) << again.icp.message;
  EXPECT_LT(s.region_error(*tracker.pose(), truth), 0.0015);
}

TEST(DepthTracker, RejectsCloudsOutsideTheRoiAndBadOptions) {
  TrackingScene s;
  DepthTrackerOptions o;
  o.roi_min = Vec3(5, 5, 5);
  o.roi_max = Vec3(6, 6, 6);
  DepthTracker tracker(s.region, Rigid::Identity(), o);
  Points c = s.clouds(Rigid::Identity(), 1, 6)[0];
  expect_throw_with<InputError>([&] { tracker.process(c, s.camera_to_world); }, "inside the region of interest");
  DepthTrackerOptions bad;
  bad.smoothing_clouds = 0;
  expect_throw_with<InputError>([&] { DepthTracker(s.region, Rigid::Identity(), bad); }, "smoothing_clouds");
  bad = DepthTrackerOptions{};
  bad.roi_max = bad.roi_min;
  expect_throw_with<InputError>([&] { DepthTracker(s.region, Rigid::Identity(), bad); }, "roi_max");
}
