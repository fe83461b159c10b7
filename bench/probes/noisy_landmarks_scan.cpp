// Probe (issues 10 and 14): a scene's supine side as uncertainty sampling draws it (1.5 mm of
// noise per landmark coordinate, 1 mm of depth noise along the scan's normals), registered once
// per seed with the balanced preset; prints whether it converged, the worst tumour, and the
// surface step's stop and its residual per projection. It found the fold beside a noisy landmark
// that made pose-free surface steps stall (BENCHMARKS.md, "Landmarks on the scan").
//   noisy_landmarks_scan SCENE.yaml DEPTH_MM LANDMARK_MM SEEDS [FIRST_SEED]
// PROBE_NOLOS=1: the landmarks taken as given (SurfaceStepOptions::landmarks_on_scan off, as
// before d85fc4a). PROBE_V=1: every Newton iteration of the surface step.
// Build as bench/probes/suite_run_trace.cpp (same libraries).
#include <cstdio>
#include <cstdlib>
#include <random>
#include <string>

#include "breast_tumour_registration/geometry/vertex_normals.h"
#include "breast_tumour_registration/io/scene.h"
#include "breast_tumour_registration/registration/registration_engine.h"

using namespace btr;

int main(int argc, char** argv) {
  if (argc < 5) {
    std::fprintf(stderr, "usage: noisy_landmarks_scan SCENE.yaml DEPTH_MM LANDMARK_MM SEEDS [FIRST_SEED]\n");
    return 2;
  }
  const Scene s = load_scene(argv[1]);
  const double depth = std::atof(argv[2]) * 1e-3, landmark_sd = std::atof(argv[3]) * 1e-3;
  const int seeds = std::atoi(argv[4]), first = argc > 5 ? std::atoi(argv[5]) : 1;
  RegistrationEngine engine(s);
  RegistrationOptions ro = preset_options("balanced");
  if (std::getenv("PROBE_NOLOS")) ro.surface.landmarks_on_scan = false;
  const bool verbose = std::getenv("PROBE_V") != nullptr;
  for (int k = first; k < first + seeds; ++k) {
    std::mt19937 rng(static_cast<unsigned>(k));
    std::normal_distribution<double> z(0, 1);
    Scene c = s;
    for (Eigen::Index l = 0; l < c.landmark_supine.rows(); ++l)
      for (int j = 0; j < 3; ++j) c.landmark_supine(l, j) += landmark_sd * z(rng);
    if (depth > 0) displace_along_normals(*c.supine_surface, depth, [&] { return z(rng); });
    const auto r = engine.solve(c, ro, [&](const std::string& step, const IterationInfo& it) {
      if (verbose && step.rfind("surface", 0) == 0)
        std::printf("    it %d energy %.6e J |grad| %.2e N alpha %.3g step %.3f mm inverted %ld\n", it.iteration, it.energy,
                    it.gradient_norm, it.alpha, it.step_norm * 1e3, it.inverted);
      return true;
    });
    double worst = 0;
    for (const auto& t : r.tumours) worst = std::max(worst, t.centroid_distance);
    std::printf("seed %d: %s worst %.3f mm, E %.0f, scan noise %.3f mm, denoised %d, landmarks moved onto the scan %d\n", k,
                r.converged ? "converged" : "NC", worst * 1e3, r.estimated_youngs_modulus, r.supine_noise * 1e3,
                static_cast<int>(r.supine_denoised), r.landmarks_moved_onto_scan);
    for (const auto& rep : r.reports) {
      if (rep.name.rfind("surface", 0) != 0) continue;
      std::printf("  %s: %s\n  held from projection %d, residuals [mm]:", rep.name.c_str(), rep.stop_reason.c_str(), rep.sliding_held_from);
      for (double d : rep.projection_residuals) std::printf(" %.3f", d * 1e3);
      std::printf("\n");
    }
    std::fflush(stdout);
  }
}
