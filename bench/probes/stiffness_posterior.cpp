// Is the stiffness estimate's spread what StiffnessEstimate::log_sd says? For a scene with
// `youngs_modulus: estimate` and a known generating E, the supine landmarks are moved by
// N(0, sd) per axis K times; each copy's estimate, its log_sd and z = ln(E_k / E_true) / log_sd
// are printed, then the RMS of z (about 1 where the sd is right; the mean of ln(E_k / E_true)
// is the bias that model error, e.g. a Poisson's ratio off the truth's, leaves).
// Build as bench/probes/suite_run_trace.cpp, then:
//   /tmp/post PHANTOM/scene_estimated.yaml 917 8 1.5     # scene true-E copies landmark-sd-mm
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <random>
#include "breast_tumour_registration/io/scene.h"
#include "breast_tumour_registration/registration/registration_pipeline.h"
#include "breast_tumour_registration/registration/stiffness_step.h"
using namespace btr;
int main(int argc, char** argv) {
  if (argc < 5) return 2;
  const Scene scene = load_scene(argv[1]);
  const double e_true = std::atof(argv[2]), sd = std::atof(argv[4]) * 1e-3;
  const int copies = std::atoi(argv[3]);
  std::vector<std::string> w;
  const RegistrationModel model = prepare_model(scene, w);
  StiffnessOptions so = RegistrationOptions().stiffness;
  so.min_youngs_modulus = (*scene.youngs_modulus_range)[0];
  so.max_youngs_modulus = (*scene.youngs_modulus_range)[1];
  std::mt19937 rng(7);
  std::normal_distribution<double> z(0, 1);
  double sum_z2 = 0, sum_d = 0;
  int n = 0;
  for (int k = 0; k <= copies; ++k) {  // copy 0: the landmarks as given
    Points supine = scene.landmark_supine;
    if (k > 0)
      for (Eigen::Index i = 0; i < supine.size(); ++i) supine.data()[i] += sd * z(rng);
    const StiffnessEstimate e = estimate_stiffness(model, *scene.prone_gravity, scene.landmark_anchors, supine, so);
    const double d = std::log(e.youngs_modulus / e_true), s = e.log_sd(sd);
    std::printf("copy %d: E %.0f Pa (ln ratio %+.3f), misfit %.3f mm, |dr/dlnE| %.3f mm, log_sd %.3f, z %+.2f, %zu candidates, %.1f s\n", k,
                e.youngs_modulus, d, e.misfit * 1e3, e.landmark_sensitivity * 1e3, s, s > 0 ? d / s : NAN, e.evaluations.size(),
                e.seconds);
    std::fflush(stdout);
    if (k > 0 && s > 0) {
      sum_z2 += d * d / (s * s);
      sum_d += d;
      ++n;
    }
  }
  std::printf("%d copies: rms z %.2f, mean ln(E/E_true) %+.3f\n", n, std::sqrt(sum_z2 / n), sum_d / n);
}
