// btr_bench_tracking: the node's per-cloud tracking (DepthTracker: transform, ROI crop,
// warm-started ICP of the chest ring) on rendered 640 x 480 depth clouds of the phantom with
// 1 mm noise. Reports the first alignment from an offset pose (time, rotation and translation
// error), the steady-state per-cloud time (median, 95th percentile) and accuracy, and the
// resident memory after 100 and after N clouds.
#include <CLI/CLI.hpp>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <string>

#include "breast_tumour_registration/registration/simulation_mesh.h"
#include "breast_tumour_registration/base/errors.h"
#include "breast_tumour_registration/geometry/surface_attachment.h"
#include "breast_tumour_registration/io/scene.h"
#include "breast_tumour_registration/registration/depth_tracker.h"
#include "breast_tumour_registration/simulation/depth_camera.h"
#include "breast_tumour_registration/simulation/phantom_scene.h"

using namespace btr;

static double percentile(std::vector<double> v, double p) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0.0 : v[std::min(v.size() - 1, static_cast<size_t>(p * (v.size() - 1) + 0.5))];
}

static long rss_kib() {
  std::ifstream s("/proc/self/status");
  std::string line;
  while (std::getline(s, line))
    if (line.rfind("VmRSS:", 0) == 0) return std::stol(line.substr(6));
  return -1;
}

static Rigid pose(double x, double y, double z, double roll, double pitch, double yaw) {
  return rigid_from_rpy(Vec3(x, y, z), Vec3(roll, pitch, yaw));
}

int main(int argc, char** argv) {
  CLI::App app{"Benchmark the depth tracking of the registration node on rendered clouds."};
  std::string scene_path;
  int frames = 300, memory_frames = 10000;
  double voxel = 0.002, margin = 0.015, spacing = 0.002;
  int iterations = 10, smoothing = 10;
  app.add_option("--scene", scene_path, "phantom scene (default: generate one, 6 mm cells, in /tmp)");
  app.add_option("--frames", frames, "steady-state clouds timed")->capture_default_str();
  app.add_option("--memory-frames", memory_frames, "clouds processed before the second memory reading")->capture_default_str();
  app.add_option("--voxel-size", voxel, "[m]")->capture_default_str();
  app.add_option("--margin", margin, "track only chest-ring points this far from the prone breast [m]")->capture_default_str();
  app.add_option("--spacing", spacing, "rigid-region sample spacing [m]")->capture_default_str();
  app.add_option("--smoothing", smoothing, "poses averaged (DepthTrackerOptions::smoothing_clouds)")->capture_default_str();
  app.add_option("--iterations", iterations, "ICP iterations per cloud once locked")->capture_default_str();
  CLI11_PARSE(app, argc, argv);
  try {
    if (scene_path.empty()) {
      PhantomSceneOptions o;
      o.phantom.tet.cell_size = 0.006;
      write_phantom_scene("/tmp/btr_bench_tracking_scene", o);
      scene_path = "/tmp/btr_bench_tracking_scene/scene.yaml";
    }
    const Scene scene = load_meshed_scene(scene_path);
    if (!scene.supine_surface || !scene.supine_rigid || !scene.prone_rigid)
      throw InputError("the scene needs supine.surface, supine.chest_ring and chest_ring");
    const Rigid T_wp = pose(0.10, -0.05, 0.75, 0, 0, 20 * M_PI / 180);  // patient in the world (as btr_make_bag)
    const SurfaceMesh s1 = transform_surface(T_wp, *scene.supine_surface), s2 = transform_surface(T_wp, *scene.supine_rigid);
    const Rigid T_wc = look_at(T_wp * Vec3(0.0, -0.12, 0.45), T_wp * Vec3(0.0, 0.0, 0.02), T_wp.linear() * Vec3(0, 1, 0));
    const PinholeCamera cam;
    const Points clean = render_depth({&s1, &s2}, cam, T_wc);
    std::mt19937 rng(7);
    std::vector<Points> noisy(30, clean);
    for (auto& c : noisy) add_depth_noise(c, 1e-3, rng);
    const SurfaceSamples region = rigid_region_samples(*scene.prone_rigid, boundary_surface(scene.prone), margin, spacing);
    std::printf("rigid region: %ld samples of the chest ring (2 mm apart) farther than %.0f mm from the prone breast\n\n",
                static_cast<long>(region.points.rows()), margin * 1e3);
    DepthTrackerOptions opt;
    opt.voxel_size = voxel;
    opt.max_iterations = iterations;
    opt.smoothing_clouds = smoothing;
    // Error of a tracked pose T against the truth: rotation angle, translation at the
    // model origin (the breast base centre) and the largest displacement of a rigid-region
    // sample (what "on the rigid region" means in the tables).
    struct PoseError {
      double rot_deg, trans_mm, region_mm;
    };
    auto error = [&](const Rigid& T) {
      const Rigid e = T * T_wp.inverse();
      return PoseError{rotation_angle(e) * 180 / M_PI, e.translation().norm() * 1e3,
                       max_displacement(T, T_wp, region.points) * 1e3};
    };

    std::printf("| first alignment from | accepted after [clouds] | time of that cloud [ms] | its error: rot [deg] / trans [mm] / region max [mm] | within 0.5 deg and 0.5 mm on the region after [clouds] (processing time [ms]) | after 30 clouds: rot [deg] / trans [mm] / region max [mm] |\n|---|---|---|---|---|---|\n");
    for (const auto& [name, offset] : std::vector<std::pair<std::string, Rigid>>{
             {"15 deg about z, 10 mm along x", pose(0.01, 0, 0, 0, 0, 15 * M_PI / 180)},
             {"15 deg about x, 10 mm along z", pose(0, 0, 0.01, 15 * M_PI / 180, 0, 0)},
             {"15 deg about y, 10 mm along y", pose(0, 0.01, 0, 0, 15 * M_PI / 180, 0)}}) {
      DepthTracker tracker(region, T_wp * offset, opt);
      int n = 0, within = -1;
      double ms = 0, total_ms = 0, within_ms = 0;
      PoseError first{};
      while (n < 30) {
        Points c = noisy[n % noisy.size()];
        const auto t0 = std::chrono::steady_clock::now();
        tracker.process(c, T_wc);
        const double t = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
        total_ms += t;
        ++n;
        if (!tracker.pose()) continue;
        const PoseError e = error(*tracker.pose());
        if (ms == 0) {
          ms = t;
          first = e;
          std::printf("| %s | %d | %.0f | %.3f / %.3f / %.3f ", name.c_str(), n, ms, e.rot_deg, e.trans_mm, e.region_mm);
        }
        if (within < 0 && e.rot_deg <= 0.5 && e.region_mm <= 0.5) {
          within = n;
          within_ms = total_ms;
        }
      }
      if (ms == 0) {
        std::printf("| %s | not within 30 clouds | | | | |\n", name.c_str());
        continue;
      }
      const PoseError e1 = error(*tracker.pose());
      if (within > 0) std::printf("| %d (%.0f) ", within, within_ms);
      else std::printf("| not within 30 clouds ");
      std::printf("| %.3f / %.3f / %.3f |\n", e1.rot_deg, e1.trans_mm, e1.region_mm);
    }

    // Steady state, warm-started from a locked pose.
    DepthTracker tracker(region, T_wp * pose(0.01, 0, 0, 0, 0, 0.1), opt);
    for (int i = 0; i < 10; ++i) {
      Points c = noisy[i % noisy.size()];
      tracker.process(c, T_wc);
    }
    std::vector<double> total, filter, icp, rot, trans, reg, raw_rot, raw_reg;
    Vec3 mean_rotvec = Vec3::Zero(), mean_trans = Vec3::Zero();
    long rss100 = 0;
    int accepted = 0;
    const int n_total = std::max(frames, memory_frames);
    for (int i = 0; i < n_total; ++i) {
      Points c = noisy[i % noisy.size()];
      const auto t0 = std::chrono::steady_clock::now();
      const TrackingResult r = tracker.process(c, T_wc);
      const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
      if (i < frames) {
        total.push_back(ms);
        filter.push_back(r.seconds_filter * 1e3);
        icp.push_back(r.seconds_icp * 1e3);
        accepted += r.accepted;
        const PoseError e = error(*tracker.pose());
        rot.push_back(e.rot_deg);
        trans.push_back(e.trans_mm);
        reg.push_back(e.region_mm);
        const PoseError raw = error(*tracker.latest_pose());
        raw_rot.push_back(raw.rot_deg);
        raw_reg.push_back(raw.region_mm);
        const Rigid d = *tracker.pose() * T_wp.inverse();
        const Eigen::AngleAxisd aa(d.linear());
        mean_rotvec += aa.angle() * aa.axis() * 180 / M_PI / frames;
        mean_trans += d.translation() * 1e3 / frames;
      }
      if (i + 1 == 100) rss100 = rss_kib();
    }
    const long rssN = rss_kib();
    std::printf("\n| clouds | accepted | per cloud median [ms] | p95 [ms] | filter median [ms] | ICP median [ms] | points in ROI | rotation error median / max [deg] | translation error median / max [mm] | region max displacement median / max [mm] |\n|---|---|---|---|---|---|---|---|---|---|\n");
    long in_roi = 0;
    for (Eigen::Index i = 0; i < clean.rows(); ++i) in_roi += clean.row(i).allFinite();
    std::printf("| %d | %d | %.1f | %.1f | %.1f | %.1f | %ld | %.3f / %.3f | %.3f / %.3f | %.3f / %.3f |\n", frames, accepted,
                percentile(total, 0.5), percentile(total, 0.95), percentile(filter, 0.5), percentile(icp, 0.5), in_roi,
                percentile(rot, 0.5), percentile(rot, 1.0), percentile(trans, 0.5), percentile(trans, 1.0),
                percentile(reg, 0.5), percentile(reg, 1.0));
    std::printf("\neach cloud's own pose (no smoothing): rotation error median / max %.3f / %.3f deg, region max displacement median / max %.3f / %.3f mm\n",
                percentile(raw_rot, 0.5), percentile(raw_rot, 1.0), percentile(raw_reg, 0.5), percentile(raw_reg, 1.0));
    std::printf("\nmean error over the %d clouds (bias): rotation vector (%.3f, %.3f, %.3f) deg, translation (%.3f, %.3f, %.3f) mm\n",
                frames, mean_rotvec.x(), mean_rotvec.y(), mean_rotvec.z(), mean_trans.x(), mean_trans.y(), mean_trans.z());
    std::printf("\nresident memory after 100 clouds: %.1f MiB; after %d clouds: %.1f MiB\n", rss100 / 1024.0, n_total,
                rssN / 1024.0);
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "btr_bench_tracking: %s\n", e.what());
    return 1;
  }
}
