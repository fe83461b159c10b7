// The uncertain inputs of a registration and their default distributions (issue 14): what a
// scene's `uncertainty:` section overrides and what tumour_uncertainty.h propagates.
// SI units. Every source is independent of the others.
//
//   uncertainty:                           # optional; these are the defaults
//     youngs_modulus_range: [200, 3000]    # [Pa] log-uniform; [0, 0]: held at the material's
//     poisson_ratio_range: [0.45, 0.499]   # uniform; [0, 0]: held
//     gravity_direction_deg: 2             # sd of the tilt about each horizontal axis
//     landmark_sd_mm: 1.5                  # sd of each supine landmark, per axis
//     depth_noise_mm: 1                    # sd of the supine surface (and rigid region) along its normal
//     rigid_pose: true                     # the pose ICP fits on the rigid regions; false: held
//     discretisation: true                 # sampling: the element form's error from a nodal reference
//
// The rigid pose's distribution is the fit's own: where ICP on the rigid regions sets the pose,
// the linearisation takes IcpResult::pose_covariance, and sampling re-fits it on the rigid region
// with depth noise.
#pragma once

#include <array>

namespace btr {

struct UncertaintySources {
  /// A patient's Young's modulus nobody measured: log-uniform over this range [Pa], whatever
  /// the scene's nominal value (published breast fits lie at 200 to 300 Pa, NiftySim's
  /// fat / gland / muscle at 0.45 to 1.8 kPa). Every tissue is scaled together, keeping the
  /// regions' ratios. {0, 0}: held at the nominal value.
  std::array<double, 2> youngs_modulus_range{200, 3000};
  /// Poisson's ratio, uniform over this range (the linearisation takes the volume compliance's
  /// spread about the nominal over it: tumour_uncertainty.h). {0, 0}: held.
  std::array<double, 2> poisson_ratio_range{0.45, 0.499};
  double gravity_direction_deg = 2.0;  ///< sd of the supine gravity's tilt about each horizontal axis [deg]
  double landmark_sd = 0.0015;         ///< sd of each supine landmark's position, per axis [m] (sampling; the linear region where the pose is solved with the deformation)
  double depth_noise = 0.001;          ///< sd of the supine surface and rigid region along their normals, per vertex [m]
  /// The rigid pose ICP fits on the rigid regions, as uncertain as its fit (and, sampled, the
  /// rigid region's depth noise) makes it; false: held at its solution.
  bool rigid_pose = true;
  /// The model's own discretisation error, which no other source draws: where the region is
  /// sampled with the element volume form, the nominal inputs are registered once more with the
  /// nodal form (which locks less), and every sample is moved by its shift of each tumour (and
  /// surface vertex): SampledUncertainty::Tumour::discretisation. On truth our elements did not
  /// make (the phantom's quadratic truth, SfePy's two bodies) that shift pointed along the element
  /// form's error (cosine 0.56 to 1.00); with it the region was at its level on SfePy's bodies and
  /// over-wide below 95 % on the phantom, without it biased on both (BENCHMARKS.md, "The element
  /// form's own error in the tumour's region"). Not in the linearised region (the reference costs
  /// 2 to 4 registrations). false: left out.
  bool discretisation = true;

  bool samples_youngs_modulus() const { return youngs_modulus_range[1] > 0; }
  bool samples_poisson_ratio() const { return poisson_ratio_range[1] > 0; }
  /// The sd of ln E over the range, ln(max / min) / sqrt(12): what the linearisation takes
  /// about the nominal modulus (0 when E is held).
  double youngs_modulus_log_sd() const;
  /// Every source off.
  static UncertaintySources none();
};

/// InputError naming the field (as the scene spells it) for a range that is not
/// {0, 0} or 0 < min <= max (Poisson's ratio: max < 0.5), or a negative or non-finite sd.
void validate_uncertainty_sources(const UncertaintySources& s);

}  // namespace btr
