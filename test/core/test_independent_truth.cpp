// Issue 13: the method on truth that another finite-element code made (SfePy: quadratic
// tetrahedra on a TetGen mesh, a decoupled neo-Hookean law with a bulk penalty, fat 3400 Pa
// with a 2x gland and 6x tumours, a sheared asymmetric body without a chest ring), committed
// small in test/data (bench/make_independent_truth.py wrote it). Our own phantom's truth shares
// the method's mesh type and material; this one shares neither.
#include <random>
#include <string>

#include "breast_tumour_registration/geometry/vertex_normals.h"
#include "breast_tumour_registration/registration/registration_engine.h"
#include "breast_tumour_registration/registration/registration_pipeline.h"
#include "breast_tumour_registration/registration/stiffness_step.h"
#include "test_util.h"

using namespace btr;
using test::step_stops;
using test::worst_error;

namespace {

struct Outcome {
  double worst = 0, rigid_only = 0, axis_gap = 0;  ///< [m], [m], largest relative axis-ratio gap
  bool converged = false;
};

Outcome register_independent(const std::string& variant, const std::string& fat = "3400") {
  const Scene s = load_meshed_scene(std::string(BTR_TEST_DATA_DIR) + "/independent_truth_E" + fat + "/scene_" + variant + ".yaml");
  std::vector<std::string> warnings;
  const RegistrationModel m = prepare_model(s, warnings);
  const RegistrationResult r = run_registration(s, m, preset_options(s.preset));
  Outcome o;
  o.converged = r.converged;
  for (const auto& t : r.tumours) {
    o.worst = std::max(o.worst, t.centroid_distance);
    o.rigid_only = std::max(o.rigid_only, t.rigid_centroid_distance);
    o.axis_gap = std::max(o.axis_gap, std::abs(t.axis_ratio - t.truth_axis_ratio) / t.truth_axis_ratio);
  }
  std::printf("independent truth (SfePy, fat %s Pa), %-17s: worst tumour %.3f mm (rigid only %.3f mm), axis-ratio gap "
              "%.1f %%, %s%s\n",
              fat.c_str(), variant.c_str(), o.worst * 1e3, o.rigid_only * 1e3, 100 * o.axis_gap, r.converged ? "converged" : "not converged",
              r.steps.stiffness ? (", E estimated " + std::to_string(static_cast<int>(r.estimated_youngs_modulus)) + " Pa").c_str() : "");
  return o;
}

}  // namespace

TEST(IndependentTruth, EveryPlanBeatsRigidAlignmentAndTheUnloadedShapeBeatsTheProneShape) {
  // Measured here (load_scene meshes the prone surface at 6 mm): rigid only 1.45 to 1.60 mm; the
  // prone shape as rest 0.54 mm; unloaded 0.24 mm; with regions 0.24 mm and an axis-ratio gap of
  // 2.2 % instead of 4.8 %; regions and E estimated (3371 Pa) 0.24 mm. btr_register's 7 mm mesh:
  // BENCHMARKS.md, "Heterogeneous tissue".
  const Outcome prone = register_independent("prone"), unloaded = register_independent("unloaded"),
                regions = register_independent("unloaded_regions"), estimated = register_independent("estimated_regions");
  for (const Outcome* o : {&prone, &unloaded, &regions, &estimated}) {
    EXPECT_TRUE(o->converged);
    EXPECT_LT(o->worst, 0.5 * o->rigid_only);  // registration never worse than doing less
  }
  EXPECT_LT(unloaded.worst, 0.7 * prone.worst);
  EXPECT_LT(estimated.worst, 0.35e-3);
  // The tumours' stiffness keeps their shape: the gap to the truth's axis ratio halves.
  EXPECT_LT(regions.axis_gap, 0.7 * unloaded.axis_gap);
  EXPECT_LT(estimated.axis_gap, 0.05);
}

TEST(IndependentTruth, AtSoftFatTheFullMethodNeedsTheRegionsTheStiffnessAndALockingFreeVolumeTerm) {
  // Fat at 1000 Pa (prone sag 8 mm): the prone shape as rest is barely better than rigid
  // alignment. The unloaded shape at an estimated E with the tissue regions is better, and far
  // better with the volume term on nodal averages: the truth's quadratic elements do not lock
  // at nu = 0.49, the method's linear ones do with the element form (the default at 0.49, for
  // speed). Our own phantom cannot show this: its truth locks in the same way. Figures printed;
  // BENCHMARKS.md, "Heterogeneous tissue".
  const Outcome prone = register_independent("prone", "1000"), full = register_independent("estimated_regions", "1000"),
                nodal = register_independent("estimated_regions_nodal", "1000");
  EXPECT_TRUE(full.converged);
  EXPECT_TRUE(nodal.converged);
  EXPECT_LT(prone.worst, prone.rigid_only);
  EXPECT_LT(full.worst, 0.5 * prone.worst);
  EXPECT_LT(nodal.worst, 0.5 * full.worst);
  EXPECT_LT(nodal.worst, 0.6e-3);
}

namespace {

/// The SfePy body (fat 3400 Pa, prone shape as rest, no chest ring: the pose is free) registered
/// with the method's modulus at `youngs` and the skin's sliding as `sliding`.
RegistrationResult register_sliding(double youngs, SkinSliding sliding) {
  static const Scene s = load_meshed_scene(std::string(BTR_TEST_DATA_DIR) + "/independent_truth_E3400/scene_prone.yaml");
  std::vector<std::string> warnings;
  RegistrationModel m = prepare_model(s, warnings);
  scale_stiffness(m, youngs / m.material.youngs_modulus);
  RegistrationOptions o = preset_options("balanced");
  o.surface.sliding = sliding;
  return run_registration(s, m, o);
}

}  // namespace

TEST(SurfaceStep, HeldSlidingConvergesWhereFreeSlidingCreepsAndEndsNoFartherFromTheTruth) {
  // Issue 10: the method told 300 Pa on a body whose fat is 3400 Pa (as uncertainty sampling
  // draws it). With free sliding the skin creeps along the scan (contraction about 0.98 per
  // projection) until the projection cap; its limit lies farther from the truth than the state
  // where it settled. Held where it settled, the alternation converges in a few projections.
  const RegistrationResult free = register_sliding(300, SkinSliding::Free);
  const RegistrationResult held = register_sliding(300, SkinSliding::HeldWhereSettled);
  const StepReport &fs = free.reports.back(), &hs = held.reports.back();
  ASSERT_EQ(hs.name, "surface (pose free)") << step_stops(held);
  std::printf("SfePy body, method at 300 Pa: free sliding %s after %d projections (contraction %.3f), worst tumour %.3f mm; "
              "held from projection %d: %s after %d, worst %.3f mm\n",
              fs.converged ? "converged" : "not converged", fs.outer_iterations, fs.contraction, worst_error(free) * 1e3,
              hs.sliding_held_from, hs.converged ? "converged" : "not converged", hs.outer_iterations,
              worst_error(held) * 1e3);
  EXPECT_FALSE(fs.converged) << step_stops(free);
  EXPECT_GE(fs.contraction, 0.9);
  EXPECT_TRUE(held.converged) << step_stops(held);
  EXPECT_GT(hs.sliding_held_from, 0);
  EXPECT_LT(hs.outer_iterations, fs.outer_iterations / 2);
  EXPECT_LE(worst_error(held), worst_error(free) + 0.1e-3);
}

TEST(SurfaceStep, HeldSlidingKeepsTheSettledStateWhereTheFreeLimitLiesFarther) {
  // The method told the body's own fat modulus. After 4 projections the steps read a fast
  // contraction (0.34) and a skin settled within the tolerance, but the free limit (checked by
  // one Newton step without the point springs: verify_free_limit) lies 0.22 mm RMS away. Free
  // sliding goes on to it (35 projections); HeldWhereSettled holds the sliding where the steps
  // settled and converges there. Before the check both stopped at projection 4, "converged".
  // On this independent truth the held state is the nearer one (0.55 against 0.74 mm).
  const RegistrationResult free = register_sliding(3400, SkinSliding::Free);
  const RegistrationResult held = register_sliding(3400, SkinSliding::HeldWhereSettled);
  const StepReport &fs = free.reports.back(), &hs = held.reports.back();
  EXPECT_TRUE(free.converged) << step_stops(free);
  EXPECT_TRUE(held.converged) << step_stops(held);
  EXPECT_TRUE(fs.free_limit_missed && hs.free_limit_missed);
  EXPECT_EQ(fs.sliding_held_from, 0);
  EXPECT_GT(hs.sliding_held_from, 0);
  EXPECT_EQ(hs.sliding_held_from, hs.free_limit_checked_at);
  EXPECT_GT(fs.outer_iterations, hs.outer_iterations);
  EXPECT_LE(worst_error(held), worst_error(free) + 0.1e-3);
  std::printf("SfePy body, method at 3400 Pa: free sliding to its limit in %d projections, worst %.3f mm; held from %d, "
              "converged after %d, worst %.3f mm\n",
              fs.outer_iterations, worst_error(free) * 1e3, hs.sliding_held_from, hs.outer_iterations, worst_error(held) * 1e3);
}

TEST(SurfaceStep, NoisyLandmarksOnANoisyScanNoLongerFoldTheSkinBesideThem) {
  // Issues 10 and 14: the supine side as uncertainty sampling draws it (1.5 mm per landmark
  // coordinate, 1 mm of depth noise), SfePy's fat 1000 Pa body, E estimated, nodal, balanced.
  // Taken as given, a landmark's noise along the normal pulled its vertex off the scan against
  // the skin springs beside it; the skin there folded and flipped at every projection, and the
  // pose-free surface step stalled (this draw; 2 of 12 and 6 of 16 on the two SfePy bodies,
  // BENCHMARKS.md, "Landmarks on the scan"). Moved onto the scan, the targets let it converge,
  // its error within 0.2 mm of the stalled state's (2.20 against 2.13 mm for this draw; the
  // means over the draws were the same).
  const Scene s = load_scene(std::string(BTR_TEST_DATA_DIR) + "/independent_truth_E1000/scene_estimated_regions_nodal.yaml");
  Scene noisy = s;
  std::mt19937 rng(1);  // bench/probes/noisy_landmarks_scan.cpp's first seed
  std::normal_distribution<double> z(0, 1);
  for (Eigen::Index l = 0; l < noisy.landmark_supine.rows(); ++l)
    for (int j = 0; j < 3; ++j) noisy.landmark_supine(l, j) += 0.0015 * z(rng);
  displace_along_normals(*noisy.supine_surface, 0.001, [&] { return z(rng); });
  RegistrationEngine engine(s);
  RegistrationOptions o = preset_options("balanced");
  const RegistrationResult on = engine.solve(noisy, o);
  o.surface.landmarks_on_scan = false;
  const RegistrationResult given = engine.solve(noisy, o);
  std::printf("noisy landmarks and scan: moved onto the scan %s, worst tumour %.3f mm; as given %s, %.3f mm\n",
              on.converged ? "converged" : "not converged", worst_error(on) * 1e3, given.converged ? "converged" : "not converged",
              worst_error(given) * 1e3);
  ASSERT_TRUE(on.pose_solved_with_surface);
  EXPECT_EQ(on.landmarks_moved_onto_scan, s.landmark_supine.rows());
  EXPECT_EQ(given.landmarks_moved_onto_scan, 0);
  EXPECT_TRUE(on.converged) << step_stops(on);
  EXPECT_FALSE(given.converged) << "the draw no longer shows the fold: choose another";
  EXPECT_LT(worst_error(on), worst_error(given) + 0.2e-3);
}
