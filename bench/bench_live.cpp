// btr_bench_live: the demo's live registration without ROS and without tracking. The supine
// skin (and chest ring) of a scene is rendered by a 640 x 480 depth camera 0.45 m above it, as
// btr_make_bag renders the demo's bag; each scan gets its own depth noise, and the engine
// registers it with the exact pose (solve_live with the true alignment), so what varies from
// scan to scan is the noise the surface step projects onto, not the tracked pose. Reports per
// scan the worst tumour error, the surface step's stop and projections, and the median and
// range over the scans.
//   btr_bench_live SCENE [--scans 9] [--noise-mm 1] [--smoothing-px 2] [-p balanced] [--anderson-depth 5]
#include <CLI/CLI.hpp>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <random>
#include <vector>

#include "breast_tumour_registration/base/errors.h"
#include "breast_tumour_registration/registration/live_scene.h"
#include "breast_tumour_registration/registration/registration_engine.h"
#include "breast_tumour_registration/simulation/depth_camera.h"

using namespace btr;

static double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0.0 : (v[(v.size() - 1) / 2] + v[v.size() / 2]) / 2;
}

int main(int argc, char** argv) {
  CLI::App app{"Register noisy rendered depth scans of a scene's supine side with the exact pose; the spread over scans."};
  std::string scene_path, preset = "balanced", normals = "interpolated";
  int scans = 9, anderson = -1;
  double noise_mm = 1.0, smoothing = LiveSceneOptions{}.smoothing_pixels;
  unsigned seed = 1;
  app.add_option("scene", scene_path, "scene file (YAML) with supine.surface")->required();
  app.add_option("--scans", scans, "noisy scans")->check(CLI::Range(1, 10000))->capture_default_str();
  app.add_option("--noise-mm", noise_mm, "depth noise sigma [mm]")->check(CLI::Range(0.0, 100.0))->capture_default_str();
  app.add_option("-p,--preset", preset, "fast, balanced or accurate")->capture_default_str();
  app.add_option("--anderson-depth", anderson, "surface step's Anderson depth (default: the preset's; 0: plain alternation)");
  app.add_option("--smoothing-px", smoothing, "the scan's Gaussian smoothing before registration [px] (0: none)")
      ->check(CLI::Range(0.0, 50.0))->capture_default_str();
  app.add_option("--seed", seed, "first scan's noise seed")->capture_default_str();
  app.add_option("--target-normals", normals, "the point-to-plane springs' normal on the scan's mesh")
      ->check(CLI::IsMember({"face", "interpolated"}))->capture_default_str();
  CLI11_PARSE(app, argc, argv);
  try {
    const Scene scene = load_scene(scene_path);
    if (!scene.supine_surface) throw InputError(scene_path + ": field 'supine.surface' is needed to render a depth scan");
    RegistrationOptions opt = preset_options(preset);
    if (anderson >= 0) opt.surface.anderson_depth = anderson;
    opt.surface.target_normals = normals == "face" ? MeshNormals::Face : MeshNormals::Interpolated;
    RegistrationEngine engine(scene);
    std::vector<const SurfaceMesh*> seen = {&*scene.supine_surface};
    if (scene.supine_rigid) seen.push_back(&*scene.supine_rigid);
    const Rigid camera = look_at(Vec3(0.0, -0.12, 0.45), Vec3(0.0, 0.0, 0.02), Vec3(0, 1, 0));
    PinholeCamera cam;  // 640 x 480, f = 525 px, as the demo's bag
    const Points clean = render_depth(seen, cam, camera);  // camera frame
    const RegistrationResult file = engine.solve(opt);
    double file_worst = 0;
    for (const auto& t : file.tumours) file_worst = std::max(file_worst, t.centroid_distance);
    std::printf("smoothing %.1f px, %s normals; ", smoothing, normals.c_str());
    std::printf("scene %s, preset %s, depth noise %.2f mm, %d scans; the scene's own supine surface: worst tumour %.3f mm\n",
                scene_path.c_str(), preset.c_str(), noise_mm, scans, file_worst * 1e3);
    std::vector<double> worst, seconds, projections;
    int converged = 0;
    for (int k = 0; k < scans; ++k) {
      Points noisy = clean;
      std::mt19937 rng(seed + static_cast<unsigned>(k));
      if (noise_mm > 0) add_depth_noise(noisy, noise_mm * 1e-3, rng);
      LiveSceneOptions live;
      live.smoothing_pixels = smoothing;
      LiveScan scan;
      scan.cloud = transform_points(camera, noisy);  // the scene's supine frame is the working frame
      scan.width = cam.width;
      scan.height = cam.height;
      if (k == 0) {
        const LiveScene probe = live_scene(scene, scan, live);
        std::printf("estimated depth noise of scan 0: %.3f mm (%s)\n", probe.estimated_noise * 1e3,
                    probe.smoothed ? "smoothed" : "not smoothed");
      }
      const auto t0 = std::chrono::steady_clock::now();
      const RegistrationResult r = engine.solve_live(scan, live, opt);
      seconds.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
      double w = 0;
      for (const auto& t : r.tumours) w = std::max(w, t.centroid_distance);
      worst.push_back(w * 1e3);
      const StepReport* surface = nullptr;
      for (const auto& rep : r.reports)
        if (rep.name.rfind("surface", 0) == 0) surface = &rep;
      projections.push_back(surface ? surface->outer_iterations : 0);
      converged += r.converged;
      std::printf("scan %2d: worst tumour %.3f mm, %.2f s, %s; surface: %d projections, %s\n", k, w * 1e3, seconds.back(),
                  r.converged ? "converged" : "not converged", surface ? surface->outer_iterations : 0,
                  surface ? surface->stop_reason.c_str() : "no surface step");
    }
    std::printf("over %d scans: worst tumour median %.3f mm (%.3f to %.3f), seconds median %.2f, projections median %.0f, converged %d\n",
                scans, median(worst), *std::min_element(worst.begin(), worst.end()), *std::max_element(worst.begin(), worst.end()),
                median(seconds), median(projections), converged);
    return 0;
  } catch (const InputError& e) {
    std::fprintf(stderr, "btr_bench_live: invalid input: %s\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "btr_bench_live: %s\n", e.what());
    return 1;
  }
}
