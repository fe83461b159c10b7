#include "breast_tumour_registration/io/uncertainty_sources.h"

#include <cmath>
#include <string>

#include "breast_tumour_registration/base/errors.h"

namespace btr {
namespace {

void check_sd(double v, const char* field) {
  if (!std::isfinite(v) || v < 0)
    throw InputError(std::string("uncertainty: field '") + field + "' must be finite and >= 0, got " + std::to_string(v));
}

void check_range(const std::array<double, 2>& r, double upper, const char* field, const char* what) {
  if (r[0] == 0 && r[1] == 0) return;
  if (!(std::isfinite(r[0]) && std::isfinite(r[1]) && r[0] > 0 && r[0] <= r[1] && r[1] < upper))
    throw InputError(std::string("uncertainty: field '") + field + "' must be [0, 0] (held) or [min, max] with " + what +
                     ", got [" + std::to_string(r[0]) + ", " + std::to_string(r[1]) + "]");
}

}  // namespace

double UncertaintySources::youngs_modulus_log_sd() const {
  return samples_youngs_modulus() ? std::log(youngs_modulus_range[1] / youngs_modulus_range[0]) / std::sqrt(12.0) : 0.0;
}

UncertaintySources UncertaintySources::none() {
  UncertaintySources s;
  s.youngs_modulus_range = {0, 0};
  s.poisson_ratio_range = {0, 0};
  s.gravity_direction_deg = s.landmark_sd = s.depth_noise = 0;
  s.rigid_pose = false;
  s.discretisation = false;
  return s;
}

void validate_uncertainty_sources(const UncertaintySources& s) {
  check_range(s.youngs_modulus_range, INFINITY, "youngs_modulus_range", "0 < min <= max [Pa]");
  check_range(s.poisson_ratio_range, 0.5, "poisson_ratio_range", "0 < min <= max < 0.5");
  check_sd(s.gravity_direction_deg, "gravity_direction_deg");
  check_sd(s.landmark_sd, "landmark_sd_mm");
  check_sd(s.depth_noise, "depth_noise_mm");
}

}  // namespace btr
