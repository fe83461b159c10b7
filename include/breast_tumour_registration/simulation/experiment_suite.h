// The synthetic experiments of thesis Sec. 5.2 (Table 5.1), run on the built-in phantom or
// on a user's rest model: every generating Young's modulus gives a prone and a supine
// configuration; every experiment varies one input of the registration; every run gives
// one row per tumour (centroid distance, Hausdorff, volume ratio, seconds).
#pragma once

#include <functional>
#include <iosfwd>
#include <string>
#include <vector>

#include "breast_tumour_registration/io/scene.h"
#include "breast_tumour_registration/simulation/phantom.h"
#include "breast_tumour_registration/simulation/phantom_scene.h"

namespace btr {

/// One configuration of one experiment: what it changes in the scene and the options.
struct ExperimentRun {
  std::string experiment;  ///< practical, rest_shape, rotated_gravity, misalignment, material, landmark_weight, landmark_set
  std::string setting;     ///< e.g. the method ("full", "surface") or "with_rigid" / "without_rigid"
  std::string variable;    ///< name of the swept variable (with its unit)
  std::string value;       ///< its value, as written in the CSV
  std::vector<std::string> steps;  ///< pipeline steps (empty: auto)
  /// The method's rest shape: "prone" (the prone shape, as the thesis), "rest" (the true rest
  /// shape, known only in an experiment), "unloaded" (estimated from the prone shape: the
  /// scene gives prone_gravity), "estimated" (unloaded at a Young's modulus estimated from the
  /// landmarks: youngs_modulus: estimate) or "" (the suite's default, ExperimentSuiteOptions::rest_shape).
  std::string rest_shape;
  Vec3 gravity_rotation_deg = Vec3::Zero();  ///< rotation of the method's gravity direction
  Vec3 misalignment_rotation_deg = Vec3::Zero();
  Vec3 misalignment_translation_mm = Vec3::Zero();
  double method_youngs_modulus = 3400;  ///< the registration's material [Pa]
  bool fixed_material = false;          ///< the material is the swept variable: never estimated
  double landmark_weight = 1e4;         ///< [N/m]
  std::string landmark_set = "C+O";     ///< a phantom_landmark_set name, or "all" (every landmark of the model)
};

struct ExperimentSuiteOptions {
  std::vector<std::string> experiments;  ///< empty: all
  std::vector<double> generating_youngs_moduli;  ///< empty: the thesis's 16 values
  bool quick = false;                    ///< a few values per experiment (for tests)
  double poisson_ratio = 0.49, density = 1000;
  std::string preset = "balanced";
  /// The rest shape of the runs without their own rest_shape setting: "prone" (the thesis's
  /// method), "unloaded" (the scene states the model's prone gravity: unloaded at the method's
  /// E) or "estimated" (also youngs_modulus: estimate; the material experiment, whose variable
  /// E is, unloads at its E instead).
  std::string rest_shape = "prone";
  /// Run only share `shard` (1-based) of `shards`: a contiguous block of the (generating
  /// modulus, run) items in plan order (experiment_shards.h merges the shares' CSVs).
  int shard = 1, shards = 1;
};

/// The thesis's generating Young's moduli: 200, 400, ..., 1000, 2000, ..., 12000 Pa.
const std::vector<double>& thesis_youngs_moduli();
/// Names of the experiments, in the thesis's order.
const std::vector<std::string>& experiment_names();

/// The runs of the chosen experiments (full sweeps of Table 5.1, or a few values each in
/// quick mode). Throws InputError for an unknown experiment name.
std::vector<ExperimentRun> plan_experiments(const ExperimentSuiteOptions& opt);

/// The scene of one run: `model` deformed by `conf` (prone or rest shape as the start),
/// the supine surface, landmarks and tumours of `conf`, with the run's misalignment,
/// material, gravity, landmark set and steps applied.
Scene experiment_scene(const PhantomModel& model, const PhantomConfigurations& conf, const ExperimentRun& run,
                       const std::string& preset, const std::string& default_rest_shape = "prone");

struct ExperimentRow {
  const ExperimentRun* run = nullptr;
  double generating_youngs_modulus = 0;
  std::string tumour;
  double centroid_distance_mm = 0, hausdorff_mm = 0, volume_ratio = 0, seconds = 0;
  double landmark_residual_max_mm = 0, skin_distance_mean_mm = 0;  ///< the figures the plausibility check reads
  double estimated_youngs_modulus = 0;  ///< [Pa] when the run estimated it (else 0)
  std::string status;  ///< converged, "not_converged: step: reason ...", or "failed: message"; " (implausible)" appended when flagged
};

/// CSV header and row writers (one row per run and tumour).
void write_experiment_csv_header(std::ostream& out);
void write_experiment_csv_row(std::ostream& out, const ExperimentRow& row);

/// Runs `runs` on every generating modulus of `opt` and passes every row to `sink`.
/// `progress` (optional) sees a line per generated configuration and per run. A run that
/// fails (a solver failure, a generated prone mesh with a flat element) gives rows with
/// status "failed: ..." and NaN figures; an unknown preset throws InputError.
void run_experiments(const PhantomModel& model, const ExperimentSuiteOptions& opt, const std::vector<ExperimentRun>& runs,
                     const std::function<void(const ExperimentRow&)>& sink,
                     const std::function<void(const std::string&)>& progress = {});

}  // namespace btr
