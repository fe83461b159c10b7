// Probe (issue 14): which sampled sources make uncertainty sampling's re-registrations end not
// converged. The scene is registered once (balanced), then sampled with only the sources each
// argument names: d depth noise (1 mm), n Poisson's ratio (0.45 to 0.499), l landmarks (1.5 mm),
// t gravity tilt (2 deg), all: the defaults. Same seed, so the same draws for every set.
//   sample_sources SCENE.yaml SAMPLES SET...      e.g. sample_sources S.yaml 8 d n l t dl all
// Build as bench/probes/suite_run_trace.cpp (same libraries).
#include <cstdio>
#include <cstdlib>
#include <string>

#include "breast_tumour_registration/io/scene.h"
#include "breast_tumour_registration/registration/registration_engine.h"

using namespace btr;

int main(int argc, char** argv) {
  if (argc < 4) {
    std::fprintf(stderr, "usage: sample_sources SCENE.yaml SAMPLES SET...\n");
    return 2;
  }
  const Scene s = load_scene(argv[1]);
  const int n = std::atoi(argv[2]);
  RegistrationEngine engine(s);
  const RegistrationOptions ro = preset_options("balanced");
  const RegistrationResult nominal = engine.solve(ro);
  std::printf("nominal: %s\n", nominal.converged ? "converged" : "not converged");
  for (int a = 3; a < argc; ++a) {
    const std::string set = argv[a];
    UncertaintyOptions u;
    u.enabled = true;
    if (set != "all") {
      u.sources = UncertaintySources::none();
      if (set.find('d') != std::string::npos) u.sources.depth_noise = 0.001;
      if (set.find('n') != std::string::npos) u.sources.poisson_ratio_range = {0.45, 0.499};
      if (set.find('l') != std::string::npos) u.sources.landmark_sd = 0.0015;
      if (set.find('t') != std::string::npos) u.sources.gravity_direction_deg = 2;
    }
    const SampledUncertainty su = engine.sample_uncertainty(ro, u, n, 1, nominal);
    std::printf("%-4s %d samples, %d not converged, %d failed: %s\n", set.c_str(), su.samples, su.not_converged, su.failed, su.note.c_str());
    std::fflush(stdout);
  }
}
