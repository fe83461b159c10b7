// The live registration's scene (what the node's ~register does with use_latest_cloud), tested
// without ROS: the scan replaces the supine side and the tracked pose moves what stays of it.
#include <cmath>
#include <filesystem>
#include <random>

#include "breast_tumour_registration/base/errors.h"
#include "breast_tumour_registration/geometry/organized_cloud.h"
#include "breast_tumour_registration/geometry/surface_denoising.h"
#include "breast_tumour_registration/geometry/surface_projector.h"
#include "breast_tumour_registration/registration/live_scene.h"
#include "breast_tumour_registration/registration/registration_engine.h"
#include "breast_tumour_registration/registration/registration_pipeline.h"
#include "breast_tumour_registration/simulation/depth_camera.h"
#include "breast_tumour_registration/simulation/phantom_scene.h"
#include "test_util.h"

using namespace btr;
using btr::test::expect_throw_with;
using btr::test::make_rigid;

namespace {


// The supine skin seen by a camera 0.4 m above the breast, in the working frame, where the
// scene's supine frame sits at `supine_to_working`; with `depth_noise` [m] along each pixel's
// ray (add_depth_noise, seeded).
LiveScan scan_of(const Scene& s, const Rigid& supine_to_working, double depth_noise = 0, unsigned seed = 5) {
  const SurfaceMesh skin = transform_surface(supine_to_working, *s.supine_surface);
  const Vec3 centre = skin.V.colwise().mean().transpose();
  PinholeCamera cam;
  cam.width = 80;
  cam.height = 60;
  cam.fx = cam.fy = 70;
  cam.cx = 39.5;
  cam.cy = 29.5;
  const Rigid camera_to_working = look_at(centre + supine_to_working.linear() * Vec3(0, 0, 0.4), centre, Vec3(0, 1, 0));
  Points cloud = render_depth({&skin}, cam, camera_to_working);
  if (depth_noise > 0) {
    std::mt19937 rng(seed);
    add_depth_noise(cloud, depth_noise, rng);
  }
  LiveScan scan;
  scan.cloud = transform_points(camera_to_working, cloud);
  scan.width = cam.width;
  scan.height = cam.height;
  scan.supine_to_working = supine_to_working;
  return scan;
}

}  // namespace

TEST(LiveScene, AnOrganizedScanBecomesTheSupineSurfaceAndThePoseMovesTheRest) {
  const Scene& s = btr::test::coarse_phantom_scene();
  const Rigid T = make_rigid(Vec3(3, -2, 10), Vec3(0.02, -0.01, 0.05));
  const LiveScene live = live_scene(s, scan_of(s, T));
  ASSERT_TRUE(live.scene.supine_surface);
  EXPECT_FALSE(live.scene.supine_cloud);
  EXPECT_FALSE(live.scene.supine_rigid);  // the scan replaces the supine side
  EXPECT_GT(live.scene.supine_surface->F.rows(), 100);
  EXPECT_TRUE(live.scene.steps.empty());
  EXPECT_TRUE((live.known_supine_to_model * T).matrix().isIdentity(1e-12));
  ASSERT_EQ(live.scene.landmark_supine.rows(), s.landmark_supine.rows());
  for (Eigen::Index i = 0; i < s.landmark_supine.rows(); ++i)
    EXPECT_LT((live.scene.landmark_supine.row(i).transpose() - T * Vec3(s.landmark_supine.row(i).transpose())).norm(), 1e-12);
  EXPECT_LT((live.scene.tumours[0].supine_ground_truth->V.row(0).transpose() -
             T * Vec3(s.tumours[0].supine_ground_truth->V.row(0).transpose())).norm(), 1e-12);
  // Registered with the tracked pose, the live scene lands on the truth as the file scene does.
  std::vector<std::string> warnings;
  const RegistrationModel m = prepare_model(s, warnings);
  RegistrationOptions opt = preset_options("balanced");
  opt.known_supine_to_model = live.known_supine_to_model;
  const RegistrationResult r = run_registration(live.scene, m, opt);
  EXPECT_FALSE(r.steps.rigid_icp || r.steps.rigid_landmarks);
  for (const auto& t : r.tumours) EXPECT_LT(t.centroid_distance, 1e-3) << t.name;  // a partial view of the skin
}

TEST(LiveScene, AnUnorganizedScanIsUsedAsItsFinitePointsAndLandmarksCanBeLeftOut) {
  const Scene& s = btr::test::coarse_phantom_scene();
  LiveScan scan = scan_of(s, Rigid::Identity());
  const Eigen::Index finite = finite_points(scan.cloud).rows();
  ASSERT_LT(finite, scan.cloud.rows());  // the camera sees background pixels as NaN
  scan.width = scan.height = 0;
  LiveSceneOptions o;
  o.use_landmarks = false;
  const LiveScene live = live_scene(s, scan, o);
  EXPECT_FALSE(live.scene.supine_surface);
  ASSERT_TRUE(live.scene.supine_cloud);
  EXPECT_EQ(live.scene.supine_cloud->rows(), finite);
  EXPECT_TRUE(live.scene.supine_cloud->allFinite());
  EXPECT_TRUE(live.scene.landmark_anchors.empty());
  EXPECT_EQ(live.scene.landmark_supine.rows(), 0);
}

TEST(LiveScene, AScanThatGivesNothingIsAClearError) {
  const Scene& s = btr::test::coarse_phantom_scene();
  LiveScan nan_scan;
  nan_scan.cloud = Points::Constant(12, 3, std::numeric_limits<double>::quiet_NaN());
  nan_scan.width = 4;
  nan_scan.height = 3;
  expect_throw_with<InputError>([&] { live_scene(s, nan_scan); }, "yields no surface");
  nan_scan.width = 5;
  expect_throw_with<InputError>([&] { live_scene(s, nan_scan); }, "not organized");
  nan_scan.width = nan_scan.height = 0;
  expect_throw_with<InputError>([&] { live_scene(s, nan_scan); }, "no finite point");
}

// Issue 10: a depth camera's noise kept the surface step's skin sliding (the demo's spread).
// The noise is estimated from the scan itself, and only a noisy scan is smoothed.
TEST(LiveScene, DepthNoiseIsEstimatedAndOnlyANoisyScanIsSmoothed) {
  const Scene& s = btr::test::coarse_phantom_scene();
  PinholeCamera cam;
  cam.width = 160;
  cam.height = 120;
  cam.fx = cam.fy = 140;
  cam.cx = 79.5;
  cam.cy = 59.5;
  const Rigid camera = look_at(Vec3(0.0, -0.12, 0.45), Vec3(0.0, 0.0, 0.02), Vec3(0, 1, 0));
  const Points clean = render_depth({&*s.supine_surface}, cam, camera);
  Points noisy = clean;
  std::mt19937 rng(3);
  add_depth_noise(noisy, 1e-3, rng);
  EXPECT_LT(estimate_organized_noise(clean, cam.width, cam.height), 0.1e-3);
  EXPECT_NEAR(estimate_organized_noise(noisy, cam.width, cam.height), 1e-3, 0.2e-3);
  // Smoothed, the noisy scan lies far closer to the skin it saw than it did.
  const Points smooth = smooth_organized(noisy, cam.width, cam.height, 2.0);
  const auto skin = make_mesh_projector(*s.supine_surface);
  double before = 0, after = 0;
  long n = 0;
  for (Eigen::Index i = 0; i < clean.rows(); ++i) {
    if (!noisy.row(i).allFinite()) continue;
    before += std::pow(skin->project(camera * Vec3(noisy.row(i).transpose())).distance, 2);
    after += std::pow(skin->project(camera * Vec3(smooth.row(i).transpose())).distance, 2);
    ++n;
  }
  ASSERT_GT(n, 1000);
  std::printf("depth noise 1 mm: RMS distance to the skin %.3f mm as scanned, %.3f mm smoothed\n", 1e3 * std::sqrt(before / n),
              1e3 * std::sqrt(after / n));
  EXPECT_LT(std::sqrt(after / n), 0.6 * std::sqrt(before / n));  // 0.72 -> 0.35 mm measured (3 mm pixels, a 12 mm mesh)
  for (Eigen::Index i = 0; i < clean.rows(); ++i) EXPECT_EQ(smooth.row(i).allFinite(), noisy.row(i).allFinite());
  LiveScan scan;
  scan.width = cam.width;
  scan.height = cam.height;
  scan.cloud = transform_points(camera, noisy);
  const LiveScene a = live_scene(s, scan);
  EXPECT_TRUE(a.smoothed);
  EXPECT_NEAR(a.estimated_noise, 1e-3, 0.2e-3);
  scan.cloud = transform_points(camera, clean);
  const LiveScene b = live_scene(s, scan);
  EXPECT_FALSE(b.smoothed);
  expect_throw_with<InputError>([&] { smooth_organized(clean, cam.width + 1, cam.height, 2.0); }, "not 161 x 120");
}

// A live organized scan keeps the live path's own filter (its image grid): the pipeline's mesh
// denoising (surface_denoising.h) stays out of it, even where the image-grid smoothing is off
// and the scan is noisy.
TEST(LiveScene, ALiveScanIsNotDenoisedAgainAsAMesh) {
  const Scene& s = btr::test::coarse_phantom_scene();
  const LiveScan scan = scan_of(s, Rigid::Identity(), 1.5e-3);
  LiveSceneOptions live;
  live.smoothing_pixels = 0;
  RegistrationEngine engine(s);
  const RegistrationResult r = engine.solve_live(scan, live, preset_options("fast"));
  EXPECT_EQ(r.supine_noise, 0);
  EXPECT_FALSE(r.supine_denoised);
  // The same triangulated scan given as a scene's supine mesh reads as noisy.
  EXPECT_GT(estimate_surface_noise(triangulate_organized(scan.cloud, scan.width, scan.height)), 0.8e-3);
}
