// btr_calibration: is the tumour's 95 % region calibrated? (issue 14) Registers scenes with a
// known truth many times, each with noisy landmarks, depth and gravity drawn from the scene's
// uncertainty sources, and counts how often the sampled and linearised regions hold the true
// centroid (calibration_study.h). bench/run_calibration.sh makes phantoms whose Young's modulus
// and Poisson's ratio are drawn over the sources' ranges; scripts/plot_calibration.py draws the
// calibration plot.
#include <CLI/CLI.hpp>

#include "breast_tumour_registration/cli_checks.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>

#include "breast_tumour_registration/base/errors.h"
#include "breast_tumour_registration/simulation/calibration_study.h"

namespace fs = std::filesystem;
using namespace btr;

namespace {

// NaN (a region not computed) left out; NaN when nothing is left.
double median(std::vector<double> v) {
  v.erase(std::remove_if(v.begin(), v.end(), [](double x) { return std::isnan(x); }), v.end());
  if (v.empty()) return std::numeric_limits<double>::quiet_NaN();
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "Register scenes with known truth again and again, each time with the supine landmarks, the depth and the\n"
      "method's gravity drawn from the scene's uncertainty sources, and count how often the 95 % regions (sampled\n"
      "and linearised) hold the true tumour centroid. Writes calibration.csv (one row per copy and tumour).\n"
      "Exit codes: 0 done, 2 invalid input, 1 other error."};
  std::vector<std::string> scene_paths;
  std::string out_dir = "calibration", preset = "balanced";
  int draws = 4, samples = 32;
  unsigned seed = 1;
  bool no_linear = false, quiet = false;
  app.add_option("scenes", scene_paths, "scene files with each tumour's supine_ground_truth")->required()->check(CLI::ExistingFile);
  app.add_option("-o,--out", out_dir, "output folder (created): calibration.csv")->capture_default_str();
  app.add_option("-p,--preset", preset, "registration preset: fast, balanced, accurate")->capture_default_str();
  app.add_option("--draws", draws, "noisy copies of every scene")->check(CLI::Range(1, 100000))->capture_default_str();
  app.add_option("--samples", samples, "sampled re-registrations per copy (0: the linearised region alone)")->check(CLI::Range(0, 100000))->capture_default_str();
  app.add_option("--seed", seed, "random seed (the copies' noise and the samples)")->capture_default_str();
  app.add_flag("--no-linear", no_linear, "skip the linearised region");
  app.add_flag("-q,--quiet", quiet, "no progress lines");
  if (const int rc = btr::cli::parse(app, argc, argv); rc >= 0) return rc;

  const auto t0 = std::chrono::steady_clock::now();
  try {
    CalibrationOptions opt;
    opt.registration = preset_options(preset);
    opt.draws = draws;
    opt.samples = samples;
    opt.seed = seed;
    opt.linear = !no_linear;
    validate_calibration_options(opt);
    std::vector<Scene> scenes;
    for (const auto& p : scene_paths) {
      scenes.push_back(load_scene(p));
      scenes.back().preset = preset;
    }
    fs::create_directories(out_dir);
    const std::string csv_path = (fs::path(out_dir) / "calibration.csv").string();
    std::ofstream csv(csv_path);
    if (!csv) throw InputError("cannot write '" + csv_path + "'");
    write_calibration_csv_header(csv);
    std::vector<CalibrationRow> rows;
    run_calibration(
        scenes, opt,
        [&](const CalibrationRow& r) {
          write_calibration_csv_row(csv, r);
          csv.flush();
          rows.push_back(r);
        },
        [&](const std::string& line) {
          if (!quiet) {
            std::printf("[calibration] %s\n", line.c_str());
            std::fflush(stdout);
          }
        });
    std::printf("[calibration] %zu rows (%zu scenes x %d copies x tumours), preset %s, %d samples per copy\n", rows.size(),
                scenes.size(), draws, preset.c_str(), samples);
    std::printf("[calibration] level  sampled: observed [95 %% interval]   linear: observed [95 %% interval]\n");
    for (double level : {0.5, 0.68, 0.8, 0.9, 0.95, 0.99}) {
      const Coverage s = observed_coverage(rows, level, true), l = observed_coverage(rows, level, false);
      std::printf("[calibration] %.2f   %.3f [%.3f, %.3f]             %.3f [%.3f, %.3f]\n", level, s.observed, s.low, s.high,
                  l.observed, l.low, l.high);
    }
    std::map<std::string, std::vector<const CalibrationRow*>> by_scene;
    for (const auto& r : rows) by_scene[r.scene].push_back(&r);
    std::printf("[calibration] per scene: median error, median 95 %% radius sampled / linear, held at 95 %% sampled / linear\n");
    for (const auto& [scene, rs] : by_scene) {
      std::vector<double> e, rsm, rl;
      int hs = 0, hl = 0;
      for (const auto* r : rs) {
        e.push_back(r->error * 1e3);
        rsm.push_back(r->sampled_radius_95 * 1e3);
        rl.push_back(r->linear_radius_95 * 1e3);
        hs += r->sampled_rank <= 0.95;
        hl += r->linear_level <= 0.95;
      }
      std::printf("[calibration] %s: %.3f mm; %.3f / %.3f mm; %d / %d of %zu\n", scene.c_str(), median(e), median(rsm),
                  median(rl), hs, hl, rs.size());
    }
    const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    std::printf("[calibration] wrote %s in %.0f s\n", fs::absolute(csv_path).string().c_str(), secs);
    return 0;
  } catch (const InputError& e) {
    std::fprintf(stderr, "btr_calibration: invalid input: %s\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "btr_calibration: error: %s\n", e.what());
    return 1;
  }
}
