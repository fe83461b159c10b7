// btr_bench_uncertainty: the linearised tumour-centroid sensitivities (tumour_uncertainty.h)
// against central differences of whole re-registrations, with the surface step run far past
// the presets' tolerances (so that the re-solves reach the equilibrium the linearisation
// differentiates, not a stopping point). Per tumour: d c / d ln E and d c / d tilt (gravity about
// the model's first horizontal axis), linear and re-solved at two step sizes, and the cost.
// --preset P runs the re-solves as a user gets them (the preset's tolerances) instead; --held
// linearises with the surface step's projections held (tumour_uncertainty.h).
//   btr_bench_uncertainty SCENE.yaml [--steps landmarks,surface] [--projection-tolerance-mm 1e-3] [--preset balanced] [--held]
#include <CLI/CLI.hpp>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "breast_tumour_registration/base/errors.h"
#include "breast_tumour_registration/registration/registration_engine.h"

using namespace btr;

int main(int argc, char** argv) {
  CLI::App app{"Linearised tumour-centroid sensitivities against re-solved finite differences."};
  std::string scene_path, steps, preset;
  bool held = false;
  double tol_mm = 1e-4;
  int max_projections = 3000;
  app.add_option("scene", scene_path, "scene file (YAML) with tumours")->required();
  app.add_option("--steps", steps, "override the scene's steps (comma list), e.g. landmarks,surface");
  app.add_option("--projection-tolerance-mm", tol_mm, "surface step: RMS skin motion between projections [mm]")
      ->capture_default_str();
  app.add_option("--max-projections", max_projections, "surface step cap")->capture_default_str();
  app.add_option("--preset", preset, "re-solve with this preset's own tolerances (default: accurate, tightened)");
  app.add_flag("--held", held, "linearise with the projections held");
  int sampling = 0;
  app.add_option("--sampling", sampling,
                 "instead of finite differences: N re-registrations per source (each alone, then all), linear against "
                 "sampled 95 % radius (with --preset)");
  CLI11_PARSE(app, argc, argv);
  try {
    Scene scene = load_scene(scene_path);
    if (!steps.empty()) {
      scene.steps.clear();
      std::stringstream ss(steps);
      std::string s;
      while (std::getline(ss, s, ',')) scene.steps.push_back(s);
    }
    RegistrationOptions o = preset_options(preset.empty() ? "accurate" : preset);
    if (preset.empty()) {
      o.landmark.newton.gradient_rel_tolerance = 1e-9;
      o.surface.newton.gradient_rel_tolerance = 1e-9;
      o.surface.projection_tolerance = tol_mm * 1e-3;
      o.surface.max_projections = max_projections;
      o.surface.stall_projections = 100;
    }
    o.uncertainty.held_projections = held;
    auto solve = [&](const Scene& s, bool uncertainty) {
      RegistrationOptions oo = o;
      oo.uncertainty.enabled = uncertainty;
      RegistrationEngine engine(s);
      const auto t0 = std::chrono::steady_clock::now();
      RegistrationResult r = engine.solve(oo);
      const double sec = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      int projections = 0;
      for (const auto& rep : r.reports) projections += rep.outer_iterations;
      std::printf("  solve: %s, %d projections, %.1f s%s%s\n", r.converged ? "converged" : "NOT converged", projections, sec,
                  r.uncertainty_note.empty() ? "" : "; ", r.uncertainty_note.c_str());
      for (const auto& rep : r.reports)
        if (!rep.converged) std::printf("    %s: %s\n", rep.name.c_str(), rep.stop_reason.c_str());
      return r;
    };
    std::printf("%s (%s, linearised with the projections %s)\nnominal:\n", scene_path.c_str(),
                preset.empty() ? "tightened accurate" : preset.c_str(), held ? "held" : "free (fixed point)");
    const RegistrationResult r = solve(scene, true);
    std::printf("  linearisation %.3f s of a %.3f s registration (%.0f %%)\n", r.uncertainty_seconds, r.seconds,
                100 * r.uncertainty_seconds / r.seconds);
    if (sampling > 0) {
      RegistrationEngine engine(scene);
      // The sources the linearisation covers, with E log-uniform about the scene's nominal
      // modulus (over a factor of 15, as the default 200 to 3000 Pa), so that the two forms
      // propagate the same distribution: landmarks and Poisson's ratio held.
      UncertaintyOptions all = o.uncertainty;
      const double e0 = scene.material.youngs_modulus;
      all.sources.youngs_modulus_range = {e0 / std::sqrt(15.0), e0 * std::sqrt(15.0)};
      all.sources.poisson_ratio_range = {0, 0};
      all.sources.landmark_sd = 0;
      struct Source {
        const char* name;
        UncertaintyOptions u;
      };
      std::vector<Source> sources(4, {"", all});
      sources[0].name = "youngs_modulus";
      sources[0].u.sources.gravity_direction_deg = sources[0].u.sources.depth_noise = 0;
      sources[1].name = "gravity_direction";
      sources[1].u.sources.youngs_modulus_range = {0, 0};
      sources[1].u.sources.depth_noise = 0;
      sources[2].name = "depth_noise";
      sources[2].u.sources.youngs_modulus_range = {0, 0};
      sources[2].u.sources.gravity_direction_deg = 0;
      sources[3].name = "all";
      for (Source& src : sources) {
        RegistrationOptions oo = o;
        oo.uncertainty = src.u;
        oo.uncertainty.enabled = true;
        const RegistrationResult nominal = engine.solve(oo);
        const SampledUncertainty su = engine.sample_uncertainty(oo, src.u, sampling, 7, nominal);
        std::printf("source %-17s %d samples (%d not converged), %.2f s each%s%s\n", src.name, su.samples, su.not_converged,
                    su.seconds_per_sample, su.note.empty() ? "" : "; ", su.note.c_str());
        for (size_t i = 0; i < nominal.tumours.size(); ++i) {
          const double lin = nominal.tumours[i].uncertainty->radius_95, smp = su.tumours[i].radius_95;
          std::printf("  %-8s 95 %% radius linear %.3f mm, sampled %.3f mm (linear / sampled %.2f); rms linear %.3f, sampled %.3f mm; "
                      "mean shift %.3f mm\n",
                      nominal.tumours[i].name.c_str(), 1e3 * lin, 1e3 * smp, lin / smp,
                      1e3 * std::sqrt(nominal.tumours[i].uncertainty->covariance.trace()),
                      1e3 * std::sqrt(su.tumours[i].covariance.trace()), 1e3 * su.tumours[i].mean_shift.norm());
        }
      }
      return 0;
    }
    const Vec3 axis = scene.gravity.normalized().unitOrthogonal();
    for (double h : {0.05, 0.2}) {
      Scene up = scene, down = scene, tp = scene, tm = scene;
      up.material.youngs_modulus *= std::exp(h);
      down.material.youngs_modulus *= std::exp(-h);
      const double t = h * 0.2;  // [rad]: 0.57 and 2.3 deg
      tp.gravity = Eigen::AngleAxisd(t, axis) * scene.gravity;
      tm.gravity = Eigen::AngleAxisd(-t, axis) * scene.gravity;
      std::printf("step: ln E +-%.2f, tilt +-%.2f deg\n", h, t * 180 / M_PI);
      const RegistrationResult a = solve(up, false), b = solve(down, false), c = solve(tp, false), d = solve(tm, false);
      for (size_t i = 0; i < r.tumours.size(); ++i) {
        const TumourUncertainty& u = *r.tumours[i].uncertainty;
        const Vec3 fe = (a.tumours[i].centroid - b.tumours[i].centroid) / (2 * h);
        const Vec3 fg = (c.tumours[i].centroid - d.tumours[i].centroid) / (2 * t);
        std::printf("  %-8s dc/dlnE [mm] linear (%7.4f %7.4f %7.4f) re-solved (%7.4f %7.4f %7.4f) |diff|/|re-solved| %.2f"
                    "   dc/dtilt [mm/rad] linear (%7.3f %7.3f %7.3f) re-solved (%7.3f %7.3f %7.3f) %.2f\n",
                    r.tumours[i].name.c_str(), 1e3 * u.d_log_youngs_modulus.x(), 1e3 * u.d_log_youngs_modulus.y(),
                    1e3 * u.d_log_youngs_modulus.z(), 1e3 * fe.x(), 1e3 * fe.y(), 1e3 * fe.z(),
                    (u.d_log_youngs_modulus - fe).norm() / fe.norm(), 1e3 * u.d_gravity_tilt[0].x(), 1e3 * u.d_gravity_tilt[0].y(),
                    1e3 * u.d_gravity_tilt[0].z(), 1e3 * fg.x(), 1e3 * fg.y(), 1e3 * fg.z(), (u.d_gravity_tilt[0] - fg).norm() / fg.norm());
      }
    }
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "btr_bench_uncertainty: %s\n", e.what());
    return 1;
  }
}
