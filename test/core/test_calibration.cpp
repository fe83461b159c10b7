// Issue 14: the uncertainty sources a scene states, and the calibration study that checks
// whether the sampled and linearised 95 % regions hold the true tumour centroid as often as
// they claim.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <sstream>
#include <stdexcept>

#include "breast_tumour_registration/base/errors.h"
#include "breast_tumour_registration/registration/registration_engine.h"
#include "breast_tumour_registration/registration/tumour_uncertainty.h"
#include "breast_tumour_registration/simulation/calibration_study.h"
#include "breast_tumour_registration/simulation/phantom_scene.h"
#include "test_util.h"

using namespace btr;
using btr::test::expect_throw_with;
using btr::test::scene_text;
using btr::test::without_chest_ring;
using btr::test::write_text;

namespace {
/// A coarse phantom (12 mm cells, 12 surface rings) generated at Young's modulus e, in a fresh
/// folder named prefix + e; returns the folder.
std::string coarse_phantom_at(double e, const std::string& prefix, ElementOrder truth_elements = ElementOrder::Linear) {
  return btr::test::write_coarse_phantom_in(btr::test::temp_dir() + "/" + prefix + std::to_string(static_cast<int>(e)), e,
                                            truth_elements);
}

/// The scene in folder d with `youngs_modulus: estimate` and the prone gravity (the model is
/// unloaded at the estimate), written as d/name.yaml; `keep_ring` false drops the chest ring.
Scene estimating_scene(const std::string& d, const std::string& name, bool keep_ring) {
  std::string text = keep_ring ? scene_text(d) : without_chest_ring(scene_text(d));
  const std::string told = "material:\n  youngs_modulus: 3400\n";
  const size_t at = text.find(told);
  if (at == std::string::npos) throw std::runtime_error(d + ": no 'youngs_modulus: 3400' to replace");
  text.replace(at, told.size(), "material:\n  youngs_modulus: estimate\n");
  write_text(d + "/" + name + ".yaml", text + "prone_gravity: [0, 0, 9.81]\n");
  return load_scene(d + "/" + name + ".yaml");
}

/// Every row of run_calibration over `scenes`: this preset, `draws` noisy copies of each scene,
/// `samples` sampled re-registrations per copy.
std::vector<CalibrationRow> calibration_rows(const std::vector<Scene>& scenes, const std::string& preset, int draws, int samples) {
  CalibrationOptions o;
  o.registration = preset_options(preset);
  o.draws = draws;
  o.samples = samples;
  std::vector<CalibrationRow> rows;
  run_calibration(scenes, o, [&](const CalibrationRow& r) { rows.push_back(r); });
  return rows;
}
}  // namespace

TEST(UncertaintySources, AScenesSectionOverridesTheDefaultsInSIAndBadFieldsAreNamed) {
  const std::string dir = btr::test::coarse_phantom_dir();
  const std::string path = dir + "/uncertainty.yaml";
  write_text(path, scene_text(dir) + "uncertainty: {youngs_modulus_range: [300, 2000], poisson_ratio_range: [0, 0], "
                                     "landmark_sd_mm: 1, depth_noise_mm: 0.5, gravity_direction_deg: 3, rigid_pose: false, "
                                     "discretisation: false}\n");
  const Scene s = load_scene(path);
  EXPECT_FALSE(s.uncertainty.rigid_pose);
  EXPECT_FALSE(s.uncertainty.discretisation);
  EXPECT_EQ(s.uncertainty.youngs_modulus_range[0], 300);
  EXPECT_EQ(s.uncertainty.youngs_modulus_range[1], 2000);
  EXPECT_FALSE(s.uncertainty.samples_poisson_ratio());
  EXPECT_DOUBLE_EQ(s.uncertainty.landmark_sd, 1e-3);
  EXPECT_DOUBLE_EQ(s.uncertainty.depth_noise, 5e-4);
  EXPECT_DOUBLE_EQ(s.uncertainty.gravity_direction_deg, 3);
  EXPECT_NEAR(s.uncertainty.youngs_modulus_log_sd(), std::log(2000.0 / 300) / std::sqrt(12.0), 1e-15);
  // Without the section: the documented defaults.
  const Scene d = load_scene(dir + "/scene.yaml");
  EXPECT_EQ(d.uncertainty.youngs_modulus_range[0], 200);
  EXPECT_EQ(d.uncertainty.youngs_modulus_range[1], 3000);
  EXPECT_DOUBLE_EQ(d.uncertainty.landmark_sd, 1.5e-3);
  EXPECT_TRUE(d.uncertainty.rigid_pose);
  EXPECT_TRUE(d.uncertainty.discretisation);
  EXPECT_FALSE(UncertaintySources::none().rigid_pose);
  EXPECT_FALSE(UncertaintySources::none().discretisation);
  const auto refused = [&](const std::string& section, const std::string& needle) {
    write_text(path, scene_text(dir) + section);
    expect_throw_with<InputError>([&] { load_scene(path); }, needle);
  };
  refused("uncertainty: {landmark_sd: 1}\n", "did you mean uncertainty.landmark_sd_mm");
  refused("uncertainty: {youngs_modulus_range: [3000, 200]}\n", "youngs_modulus_range");
  refused("uncertainty: {youngs_modulus_range: 500}\n", "uncertainty.youngs_modulus_range");
  refused("uncertainty: {poisson_ratio_range: [0.45, 0.5]}\n", "poisson_ratio_range");
  refused("uncertainty: {depth_noise_mm: -1}\n", "depth_noise_mm");
  refused("uncertainty: {depth_noise_mm: one}\n", "uncertainty.depth_noise_mm");
  refused("uncertainty: 3\n", "field 'uncertainty'");
  refused("uncertainty: {rigid_pose: maybe}\n", "field 'uncertainty.rigid_pose': expected true or false, got 'maybe'");
  refused("uncertainty: {discretisation: nodal}\n", "field 'uncertainty.discretisation': expected true or false, got 'nodal'");
  refused("uncertainty: {discretization: true}\n", "did you mean uncertainty.discretisation");
}

TEST(UncertaintySources, ProbabilityWithinASphereIsTheChiSquareCdfAndInvertsTheRadius) {
  // Isotropic: |X|^2 / s^2 is chi-square with 3 degrees of freedom.
  const double s = 2e-3;
  const Mat3 iso = s * s * Mat3::Identity();
  for (double r : {0.5, 1.0, 2.0, 3.0}) {
    const double x = r / std::sqrt(2.0);
    const double chi2_3 = std::erf(x) - std::sqrt(2.0 / M_PI) * r * std::exp(-r * r / 2);
    EXPECT_NEAR(probability_within(iso, r * s), chi2_3, 1e-4) << r;
  }
  Mat3 c;
  c << 4, 1, 0, 1, 2, 0.5, 0, 0.5, 1;
  c *= 1e-6;
  EXPECT_NEAR(probability_within(c, radius_95(c)), 0.95, 1e-4);
  EXPECT_EQ(probability_within(Mat3::Zero(), 1e-3), 1.0);
}

TEST(Calibration, WilsonIntervalAndObservedCoverageCountTheRowsAtEachLevel) {
  const auto [lo, hi] = wilson_interval(95, 100);
  EXPECT_NEAR(lo, 0.8882, 1e-3);  // the textbook values for 95 of 100
  EXPECT_NEAR(hi, 0.9785, 1e-3);
  std::vector<CalibrationRow> rows(10);
  for (int i = 0; i < 10; ++i) {
    rows[i].sampled_rank = 0.1 * i;  // 0, 0.1, ..., 0.9
    rows[i].linear_level = i < 5 ? std::nan("") : 0.99;
  }
  EXPECT_DOUBLE_EQ(observed_coverage(rows, 0.45, true).observed, 0.5);
  EXPECT_EQ(observed_coverage(rows, 0.95, true).rows, 10);
  const Coverage l = observed_coverage(rows, 0.95, false);
  EXPECT_EQ(l.rows, 5);  // rows without a linear region are left out
  EXPECT_DOUBLE_EQ(l.observed, 0.0);
  CalibrationOptions o;
  o.samples = 1;
  expect_throw_with<InputError>([&] { validate_calibration_options(o); }, "samples");
  o.samples = 0;  // the linearised region alone
  EXPECT_NO_THROW(validate_calibration_options(o));
  o.linear = false;
  expect_throw_with<InputError>([&] { validate_calibration_options(o); }, "samples");
}

// With every source held, every noisy copy is the scene itself: the same registration error
// as a plain solve, and a sampled region of radius zero that cannot hold a truth 0.01 mm away.
TEST(Calibration, WithoutSourcesEveryCopyIsTheScenesOwnRegistration) {
  Scene s = btr::test::coarse_phantom_scene();
  s.uncertainty = UncertaintySources::none();
  CalibrationOptions o;
  o.registration = preset_options("fast");
  o.draws = 2;
  o.samples = 2;
  std::vector<CalibrationRow> rows;
  run_calibration({s}, o, [&](const CalibrationRow& r) { rows.push_back(r); });
  const RegistrationResult plain = RegistrationEngine(s).solve(o.registration);
  ASSERT_EQ(rows.size(), 2 * plain.tumours.size());
  for (size_t i = 0; i < rows.size(); ++i) {
    const TumourResult& t = plain.tumours[i % plain.tumours.size()];
    EXPECT_EQ(rows[i].tumour, t.name);
    EXPECT_NEAR(rows[i].error, t.centroid_distance, 1e-12);
    EXPECT_EQ(rows[i].tilt_deg, 0.0);
    EXPECT_LT(rows[i].sampled_radius_95, 1e-12);
    EXPECT_GT(rows[i].error, 1e-5);
    EXPECT_EQ(rows[i].sampled_rank, 1.0);  // every sample nearer than the truth
    EXPECT_EQ(rows[i].youngs_modulus, s.material.youngs_modulus);  // told, not estimated
    EXPECT_EQ(rows[i].youngs_modulus_log_sd, 0.0);
  }
  // Without samples: the linearised region alone, the sampled one not computed.
  o.samples = 0;
  rows.clear();
  run_calibration({s}, o, [&](const CalibrationRow& r) { rows.push_back(r); });
  ASSERT_EQ(rows.size(), 2 * plain.tumours.size());
  for (const CalibrationRow& r : rows) {
    EXPECT_TRUE(std::isnan(r.sampled_rank) && std::isnan(r.sampled_radius_95));
    EXPECT_EQ(r.samples, 0);
    EXPECT_FALSE(std::isnan(r.linear_level));
  }
  EXPECT_EQ(observed_coverage(rows, 0.95, true).rows, 0);
  Scene no_truth = s;
  no_truth.tumours[0].supine_ground_truth.reset();
  expect_throw_with<InputError>([&] { run_calibration({no_truth}, o, [](const CalibrationRow&) {}); }, "supine_ground_truth");
}

// The quick coverage study: phantoms generated at two Young's moduli inside the sources' range
// (the method's material stays the scene's 3400 Pa), three noisy copies each, 16 samples per
// copy. With 16 exchangeable samples the "95 %" region (rank <= 0.95: within the farthest of
// the 16) holds the truth with probability 16/17 = 0.94; 30 correlated rows cannot pin that
// down, so this asks for what a region that is not grossly too small gives: >= 70 %. The
// linearised region is only reported (it misses where the model is wrong: BENCHMARKS.md).
TEST(Calibration, TheSampledRegionHoldsTheTruthOnPhantomsOfUnknownStiffness) {
  std::vector<Scene> scenes;
  for (double e : {600.0, 1800.0}) scenes.push_back(load_scene(coarse_phantom_at(e, "E") + "/scene.yaml"));
  const std::vector<CalibrationRow> rows = calibration_rows(scenes, "fast", 3, 16);
  ASSERT_EQ(rows.size(), 30u);
  const Coverage s = observed_coverage(rows, 0.95, true), l = observed_coverage(rows, 0.95, false);
  double tilt = 0;
  for (const auto& r : rows) {
    EXPECT_GE(r.sampled_rank, 0.0);
    EXPECT_LE(r.sampled_rank, 1.0);
    EXPECT_EQ(r.sampled_rank <= 0.95, r.error <= r.sampled_radius_95) << r.scene << " " << r.tumour;
    EXPECT_EQ(r.samples, 16);
    tilt = std::max(tilt, r.tilt_deg);
  }
  EXPECT_GT(tilt, 0.1);  // the copies' gravity was tilted
  std::printf("quick calibration: sampled 95 %% region held %.2f [%.2f, %.2f], linear %.2f of %d\n", s.observed, s.low,
              s.high, l.observed, s.rows);
  EXPECT_GE(s.observed, 0.7);
}

// The phantom's calibration, re-measured on truth made with quadratic elements (which our
// linear ones did not make, and which sags farther): at the study's scale (654 to 2533 Pa, E
// estimated, balanced) the 95 % region held 72 of 75 rows sampled and 75 of 75 linearised,
// with the errors 9 to 76 % larger than on the linear truth of the same bodies and the radii
// the same (BENCHMARKS.md, "The tumour's region on a truth our elements did not make"). The
// quick version: two coarse bodies, E estimated from the noisy landmarks in every copy and
// sample (measured: 17 of 20 held sampled, 19 of 20 linearised, worst error 2.5 mm; with 8
// samples a copy the sampled radius was 15 % smaller and held 14 of 20). Since the sampled
// region takes the element form's discretisation error (a nodal reference registration per copy,
// every sample moved by its shift) it held 20 of 20, median radius / error 1.86 (1.55 before).
// The scenes state the element form, whose error that reference samples: the fast preset takes
// the nodal form where a scene unloads (since 2026-12-07), and a nodal region has no reference.
TEST(Calibration, TheRegionsHoldATruthTheMethodsElementsDidNotMake) {
  std::vector<Scene> scenes;
  for (double e : {900.0, 1800.0}) {
    scenes.push_back(estimating_scene(coarse_phantom_at(e, "quadratic_E", ElementOrder::Quadratic), "estimated", true));
    scenes.back().material.volume_form = VolumeForm::Element;
  }
  const std::vector<CalibrationRow> rows = calibration_rows(scenes, "fast", 2, 16);
  ASSERT_EQ(rows.size(), 20u);
  const Coverage s = observed_coverage(rows, 0.95, true), l = observed_coverage(rows, 0.95, false);
  std::vector<double> ratio;
  double error = 0;
  for (const auto& r : rows) {
    EXPECT_TRUE(r.converged) << r.scene << " " << r.tumour;
    EXPECT_GT(r.youngs_modulus_log_sd, 0) << r.scene;
    EXPECT_FALSE(std::isnan(r.discretisation)) << r.scene << ": the nodal reference must have run and converged";
    ratio.push_back(r.sampled_radius_95 / r.error);
    error = std::max(error, r.error);
  }
  std::sort(ratio.begin(), ratio.end());
  const double median_ratio = ratio[ratio.size() / 2];
  std::printf("quadratic-truth quick calibration: sampled 95 %% region held %.2f [%.2f, %.2f], linear %.2f of %d; "
              "worst error %.2f mm, median sampled radius / error %.2f\n",
              s.observed, s.low, s.high, l.observed, s.rows, error * 1e3, median_ratio);
  EXPECT_GE(s.observed, 0.7);
  EXPECT_GE(l.observed, 0.7);
  EXPECT_LT(median_ratio, 6.0);
}

// Without a chest ring the pose is solved with the deformation, and the linear region keeps it
// free, with the landmarks that share it as a source and the skin free to slide: on two
// independent bodies and on the calibration study's ring-free phantoms it held 93 to 96 % of
// noisy copies' tumours at its 95 % level, where it held 36 to 48 % with the pose held or the
// skin's sliding held (BENCHMARKS.md, "The linear region with the pose free"). Here the quick
// version on two coarse ring-free phantoms, E estimated from the noisy landmarks and the model
// unloaded at it (40 rows, measured: 40 held, median radii 1.2 and 2.7 mm around errors of 0.5
// and 0.8 mm): it must hold most of them and not by being boundless. These phantoms' truth is
// our element form's (linear tetrahedra, which lock), so the method states that form: the
// balanced preset's nodal form (taken where a scene unloads) is the nearer model on truth our
// elements did not make, and reads a locked truth as an error (with it this held 33 of 40).
TEST(Calibration, WithoutAChestRingTheLinearRegionHoldsTheTruthAtItsLevel) {
  std::vector<Scene> scenes;
  for (double e : {600.0, 1800.0}) {
    scenes.push_back(estimating_scene(coarse_phantom_at(e, "ring_free_E"), "ring_free", false));
    scenes.back().material.volume_form = VolumeForm::Element;
    ASSERT_FALSE(scenes.back().prone_rigid);
  }
  const std::vector<CalibrationRow> rows = calibration_rows(scenes, "balanced", 4, 0);
  ASSERT_EQ(rows.size(), 40u);
  const Coverage l = observed_coverage(rows, 0.95, false);
  std::vector<double> ratio;
  for (const auto& r : rows) {
    EXPECT_GT(r.youngs_modulus_log_sd, 0) << r.scene;  // E was estimated, and its sd known
    ratio.push_back(r.linear_radius_95 / r.error);
  }
  std::sort(ratio.begin(), ratio.end());
  const double median_ratio = ratio[ratio.size() / 2];
  std::printf("ring-free quick calibration: linear 95 %% region held %.2f [%.2f, %.2f] of %d, median radius / error %.2f\n",
              l.observed, l.low, l.high, l.rows, median_ratio);
  EXPECT_GE(l.observed, 0.85);
  EXPECT_LT(median_ratio, 6.0);  // a region that holds everything by being huge is no region
}

// On an unloaded model the rest shape depends on the material: every sample that draws E
// estimates it again, so that E is sampled there too (it used to be held, which left the
// region blind to the stiffness exactly where the unloaded shape matters).
TEST(Calibration, SamplingAnUnloadedModelDrawsTheStiffnessAndUnloadsInEverySample) {
  const std::string dir = btr::test::coarse_phantom_dir();
  const std::string path = dir + "/unloaded_sources.yaml";
  write_text(path, scene_text(dir) + "prone_gravity: [0, 0, 9.81]\nuncertainty: {youngs_modulus_range: [1000, 3000], "
                                     "poisson_ratio_range: [0, 0], gravity_direction_deg: 0, landmark_sd_mm: 0, depth_noise_mm: 0}\n");
  const Scene s = load_scene(path);
  RegistrationOptions o = preset_options("fast");
  o.uncertainty.sources = s.uncertainty;
  RegistrationEngine engine(s);
  const RegistrationResult nominal = engine.solve(o);
  ASSERT_TRUE(engine.prepare(o).model.unload);
  const SampledUncertainty su = engine.sample_uncertainty(o, o.uncertainty, 3, 5, nominal);
  EXPECT_EQ(su.samples, 3);
  EXPECT_NE(su.note.find("unloaded shape estimated again in every sample"), std::string::npos) << su.note;
  for (const auto& t : su.tumours) EXPECT_GT(t.radius_95, 1e-5);  // E alone moves the tumours
}

// Where the deformation is moderate (E log-uniform within a factor 2 of the nominal, the other
// sources held, a chest ring fixing the pose), the linearised covariance is the sampled one:
// issue 14 asks for 20 %. Compared as RMS spreads (the square root of the covariances' traces)
// per tumour; 48 samples estimate an RMS to about 10 %. The accurate preset: the spread is a
// few hundredths of a millimetre, and the balanced preset's stopping (0.1 mm from the fixed
// point) blurs it (measured: ratios 1.24 to 1.38 there, 1.12 to 1.16 here).
TEST(Calibration, TheLinearisedSpreadMatchesSampledReRegistrationsWhereTheResponseIsNearlyLinear) {
  const Scene& s = btr::test::coarse_phantom_scene();
  RegistrationOptions o = preset_options("accurate");
  o.uncertainty.enabled = true;
  o.uncertainty.sources = UncertaintySources::none();
  const double e0 = s.material.youngs_modulus;
  o.uncertainty.sources.youngs_modulus_range = {e0 / 2, e0 * 2};
  RegistrationEngine engine(s);
  const RegistrationResult nominal = engine.solve(o);
  ASSERT_TRUE(nominal.converged) << btr::test::step_stops(nominal);
  ASSERT_FALSE(nominal.pose_solved_with_surface);
  const SampledUncertainty su = engine.sample_uncertainty(o, o.uncertainty, 48, 11, nominal);
  EXPECT_EQ(su.not_converged, 0) << su.note;
  for (size_t i = 0; i < nominal.tumours.size(); ++i) {
    const double lin = std::sqrt(nominal.tumours[i].uncertainty->covariance.trace());
    const double smp = std::sqrt(su.tumours[i].covariance.trace());
    std::printf("%-7s RMS spread linear %.4f mm, sampled %.4f mm, ratio %.3f\n", nominal.tumours[i].name.c_str(), lin * 1e3,
                smp * 1e3, lin / smp);
    EXPECT_GT(lin / smp, 0.8) << nominal.tumours[i].name;
    EXPECT_LT(lin / smp, 1.2) << nominal.tumours[i].name;
  }
}
