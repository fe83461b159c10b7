// Is the 95 % region calibrated? (issue 14) Each scene with a known truth is registered many
// times, each time with the inputs a user cannot know drawn from the sources' own
// distributions (the scene's `uncertainty`, uncertainty_sources.h): every supine landmark moved by its localisation
// error, the supine surface by its depth noise, the method's gravity tilted. The scene's own
// material stays the method's nominal one, so where the scenes were generated at Young's
// moduli and Poisson's ratios drawn over the sources' ranges, the method's material is off the
// truth's as a patient's would be (bench/run_calibration.sh makes such scenes). Every noisy
// copy gets a nominal registration, its linearised region and its sampled region, and every
// tumour a row: how far off the registration is, and at which level each region would just
// hold the truth. A calibrated region holds the truth at level p in a share p of the rows.
#pragma once

#include <functional>
#include <iosfwd>
#include <string>
#include <vector>

#include "breast_tumour_registration/io/scene.h"
#include "breast_tumour_registration/registration/registration_pipeline.h"

namespace btr {

struct CalibrationOptions {
  RegistrationOptions registration;  ///< the preset (the sources are each scene's `uncertainty`)
  int draws = 4;                     ///< noisy copies of every scene
  int samples = 32;                  ///< sampled re-registrations per copy (0: the linearised region alone)
  unsigned seed = 1;
  bool linear = true;                ///< also the linearised region
};
/// InputError naming the option: draws >= 1, samples >= 2 (or 0 with `linear`).
void validate_calibration_options(const CalibrationOptions& o);

struct CalibrationRow {
  std::string scene, tumour;
  int draw = 0;
  double tilt_deg = 0;  ///< the method's gravity tilt drawn for this copy
  double error = 0;     ///< registered to true centroid [m]
  /// Sampled region: its 95 % radius [m] and the truth's rank among the samples (the share of
  /// sampled centroids nearer the nominal one than the truth: the smallest level whose region
  /// holds it).
  double sampled_radius_95 = 0, sampled_rank = 0;
  /// The same from the listed sources alone, without the discretisation error (the region
  /// before UncertaintySources::discretisation), and that error's estimated size |shift| [m]
  /// (NaN where it was not estimated).
  double sampled_radius_95_sources = 0, sampled_rank_sources = 0, discretisation = 0;
  /// Linearised region: its 95 % radius [m] and P(|X| <= error) under its Gaussian (NaN when
  /// not computed).
  double linear_radius_95 = 0, linear_level = 0;
  int samples = 0, samples_not_converged = 0;
  /// The method's Young's modulus [Pa] in the nominal registration (the stiffness step's estimate
  /// where the scene asks for one, else the scene's), and the sd of ln E the landmarks leave
  /// about an estimate (0: not estimated or not known).
  double youngs_modulus = 0, youngs_modulus_log_sd = 0;
  bool converged = false;  ///< the nominal registration
  double seconds = 0;      ///< nominal registration and sampling
};

/// Every scene must give each tumour's supine ground truth (InputError otherwise). A copy whose
/// nominal registration throws gives no rows and a progress line; the study goes on.
void run_calibration(const std::vector<Scene>& scenes, const CalibrationOptions& opt,
                     const std::function<void(const CalibrationRow&)>& sink,
                     const std::function<void(const std::string&)>& progress = {});

void write_calibration_csv_header(std::ostream& out);
void write_calibration_csv_row(std::ostream& out, const CalibrationRow& row);

/// Observed coverage at a level: the share of rows whose region at that level holds the truth,
/// with its 95 % Wilson interval.
struct Coverage {
  double level = 0, observed = 0, low = 0, high = 0;
  int rows = 0;
};
/// Coverage of the sampled (rank <= level) or linearised (P <= level) regions; rows without
/// that region are left out.
Coverage observed_coverage(const std::vector<CalibrationRow>& rows, double level, bool sampled);
/// The 95 % Wilson score interval of k successes in n.
std::pair<double, double> wilson_interval(int k, int n);

}  // namespace btr
