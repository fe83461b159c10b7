// The registration method (thesis Ch. 4) on small phantoms, with real assertions on the error.
#include <filesystem>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <map>
#include <random>
#include <sstream>

#include <nlohmann/json.hpp>

#include "breast_tumour_registration/base/errors.h"
#include "breast_tumour_registration/fem/skinning_subspace.h"
#include "breast_tumour_registration/geometry/embedding.h"
#include "breast_tumour_registration/geometry/validation.h"
#include "breast_tumour_registration/geometry/shapes.h"
#include "breast_tumour_registration/geometry/surface_attachment.h"
#include "breast_tumour_registration/geometry/surface_projector.h"
#include "breast_tumour_registration/geometry/vertex_normals.h"
#include "breast_tumour_registration/io/index_io.h"
#include "breast_tumour_registration/io/mesh_io.h"
#include "breast_tumour_registration/registration/fold_advice.h"
#include "breast_tumour_registration/registration/icp_alignment.h"
#include "breast_tumour_registration/registration/simulation_mesh.h"
#include "breast_tumour_registration/registration/stiffness_grid_walk.h"
#include "breast_tumour_registration/registration/stiffness_step.h"
#include "breast_tumour_registration/registration/unload_step.h"
#include "breast_tumour_registration/simulation/phantom_scene.h"
#include "breast_tumour_registration/simulation/registration_report.h"
#include "test_util.h"

using namespace btr;
using btr::test::expect_throw_with;
using btr::test::make_rigid;
using btr::test::step_stops;
using btr::test::worst_error;

namespace {

// The shared coarse phantom scene (2.2k tetrahedra, E = 3400 Pa) and its folder.
const std::string& phantom_dir() { return btr::test::coarse_phantom_dir(); }

std::string phantom_scene_text(const std::string& base = phantom_dir()) { return btr::test::scene_text(base); }
using btr::test::without_key;

// Copies the phantom scene with extra YAML lines appended (later keys override earlier ones).
std::string scene_with(const std::string& extra, const std::string& name, const std::string& base = phantom_dir()) {
  const std::string path = base + "/" + name + ".yaml";
  std::string text = phantom_scene_text(base);
  // Drop keys that `extra` redefines, so the YAML stays valid.
  std::istringstream ex(extra);
  std::string line;
  while (std::getline(ex, line)) {
    const auto colon = line.find(':');
    if (colon == std::string::npos || line.empty() || line[0] == ' ') continue;
    text = without_key(text, line.substr(0, colon));
  }
  std::ofstream(path) << text << extra << "\n";
  return path;
}

// A coarse phantom scene whose truth our FEM made at 600 Pa (a soft breast), in its own folder.
std::string soft_phantom_dir(const std::string& name) { return btr::test::write_coarse_phantom(name, 600); }

RegistrationResult register_scene(const std::string& path, const RegistrationOptions& options) {
  const Scene s = load_meshed_scene(path);
  std::vector<std::string> warnings;
  const RegistrationModel m = prepare_model(s, warnings);
  EXPECT_TRUE(warnings.empty());
  return run_registration(s, m, options);
}
RegistrationResult register_scene(const std::string& path, const std::string& preset = "balanced") {
  return register_scene(path, preset_options(preset));
}

// Whether ln E `u` is a point of the stiffness search's grid (stiffness_grid), not a halfway point.
bool on_stiffness_grid(double u, const std::vector<double>& grid) {
  for (double g : grid)
    if (std::abs(u - g) < 1e-12) return true;
  return false;
}

}  // namespace

TEST(Kabsch, RecoversAKnownRigidTransformAndRejectsBadInput) {
  std::mt19937 rng(2);
  std::uniform_real_distribution<double> u(-0.05, 0.05);
  Points P(6, 3);
  for (int i = 0; i < 18; ++i) P.data()[i] = u(rng);
  const Rigid T = make_rigid(Vec3(10, -20, 35), Vec3(0.01, 0.02, -0.03));
  const Rigid R = kabsch(P, transform_points(T, P));
  EXPECT_LT((R.matrix() - T.matrix()).norm(), 1e-12);
  expect_throw_with<InputError>([&] { kabsch(P.topRows(2), P.topRows(2)); }, "at least 3 pairs");
  Points line(4, 3);
  for (int i = 0; i < 4; ++i) line.row(i) << i * 0.01, 0, 0;
  expect_throw_with<InputError>([&] { kabsch(line, line); }, "collinear");
}

TEST(Icp, RecoversAKnownTransformOnTheCurvedChestRing) {
  const SurfaceMesh ring = make_chest_ring(0.0745, 0.0745, 0.04, 144);
  const Rigid T = make_rigid(Vec3(4, -3, 5), Vec3(0.004, -0.003, 0.005));  // supine -> model
  const Points supine = transform_points(T.inverse(), ring.V);
  const IcpResult r = align_icp(supine, ring.V, Rigid::Identity(), IcpOptions{});
  EXPECT_TRUE(r.accepted) << r.message;
  const Rigid err = r.transform * T.inverse();
  EXPECT_LT(rotation_angle(err) * 180 / M_PI, 0.05);
  EXPECT_LT(err.translation().norm(), 5e-5);
  EXPECT_LT(r.inlier_rms, 1e-4);
}

TEST(Icp, ChecksItsResultAndRejectsBadClouds) {
  const SurfaceMesh ring = make_chest_ring(0.0745, 0.0745, 0.04, 144);
  // A cloud far away: no overlap, not accepted, with a reason.
  const Points far = transform_points(make_rigid(Vec3::Zero(), Vec3(0.5, 0, 0)), ring.V);
  const IcpResult r = align_icp(far, ring.V, Rigid::Identity(), IcpOptions{});
  EXPECT_FALSE(r.accepted);
  EXPECT_FALSE(r.message.empty());
  expect_throw_with<InputError>([&] { align_icp(Points(0, 3), ring.V, Rigid::Identity(), IcpOptions{}); }, "cloud is empty");
  Points nan = ring.V;
  nan(3, 2) = std::numeric_limits<double>::quiet_NaN();
  expect_throw_with<InputError>([&] { align_icp(nan, ring.V, Rigid::Identity(), IcpOptions{}); }, "NaN");
}

TEST(Icp, PoseCovarianceMatchesTheSpreadOverNoisyScans) {
  // The chest ring seen with 1 mm depth noise along its normals, 30 times: the pose errors'
  // Mahalanobis distance under the fit's own covariance must average 6 (chi-square, 6 dof).
  // Too small an estimate (the residuals read as noise-free) gives far more, too large far less.
  const SurfaceMesh ring = make_chest_ring(0.07, 0.06, 0.04, 144);
  const Points n = vertex_normals(ring);
  const Rigid T = make_rigid(Vec3(0.3, -0.2, 0.4), Vec3(0.004, -0.003, 0.002));  // supine -> model
  std::mt19937 rng(7);
  std::normal_distribution<double> z(0.0, 1.0);
  const int draws = 30;
  double mahalanobis = 0, sd_rotation_deg = 0;
  for (int k = 0; k < draws; ++k) {
    Points noisy = ring.V;
    for (Eigen::Index v = 0; v < noisy.rows(); ++v) noisy.row(v) += 0.001 * z(rng) * n.row(v);
    const IcpResult r = align_icp(transform_points(T.inverse(), noisy), ring.V, Rigid::Identity(), IcpOptions{});
    ASSERT_TRUE(r.accepted) << r.message;
    ASSERT_TRUE(r.pose_covariance.has_value()) << r.pose_covariance_note;
    const Rigid err = r.transform * T.inverse();  // exp(xi)
    const Vec6 xi = motion_of(err);
    mahalanobis += xi.dot(r.pose_covariance->ldlt().solve(xi)) / draws;
    sd_rotation_deg += std::sqrt(r.pose_covariance->topLeftCorner<3, 3>().trace()) * 180 / M_PI / draws;
  }
  std::printf("ICP pose covariance: mean Mahalanobis %.2f (chi-square 6 dof: 6), rotation sd %.3f deg\n", mahalanobis,
              sd_rotation_deg);
  EXPECT_GT(mahalanobis, 4.0);
  EXPECT_LT(mahalanobis, 9.0);
}

TEST(Icp, APlaneLeavesThePoseUndeterminedAndSaysSo) {
  const SurfaceMesh disc = make_chest_ring(0.07, 0.06, 0.04, 144, 1e6);  // flat to a micrometre
  const IcpResult r = align_icp(disc.V, disc.V, Rigid::Identity(), IcpOptions{});
  EXPECT_TRUE(r.accepted) << r.message;
  EXPECT_FALSE(r.pose_covariance.has_value());
  EXPECT_NE(r.pose_covariance_note.find("does not determine the pose"), std::string::npos) << r.pose_covariance_note;
}

TEST(SkinningSubspace, ReproducesAffineMapsAndKeepsTheChestWallFixed) {
  const Scene s = load_meshed_scene(phantom_dir() + "/scene.yaml");
  std::vector<bool> fixed(s.prone.V.rows(), false);
  for (int v : s.chest_wall) fixed[v] = true;
  SubspaceOptions o;
  o.handles = 20;
  const std::vector<int> seeds = {s.landmark_anchors[0].v[0], s.landmark_anchors[1].v[0]};
  const SkinningSubspace S = build_skinning_subspace(s.prone.V, 8e-4, seeds, fixed, o);
  ASSERT_EQ(S.handles.size(), 20u);
  EXPECT_EQ(S.handles[0], seeds[0]);  // seeded with the landmarks, deterministic
  EXPECT_EQ(build_skinning_subspace(s.prone.V, 8e-4, seeds, fixed, o).handles, S.handles);
  // Every handle carries the same affine map: U q must be that map at every free vertex.
  Mat3 B;
  B << 0.1, -0.2, 0.05, 0.02, 0.1, 0.3, -0.1, 0.0, 0.2;
  const Vec3 b(0.001, -0.002, 0.003);
  const Vec3 centre = s.prone.V.colwise().mean().transpose();
  Eigen::VectorXd q(S.basis.cols());
  for (size_t j = 0; j < S.handles.size(); ++j)
    for (int c = 0; c < 3; ++c) {
      q[12 * j + c] = b[c];  // constant term
      for (int a = 0; a < 3; ++a) q[12 * j + 3 * (a + 1) + c] = B(c, a) * S.radius;
    }
  const Eigen::VectorXd u = S.basis * q;
  for (Eigen::Index i = 0; i < s.prone.V.rows(); ++i) {
    const Vec3 ui = u.segment<3>(3 * i);
    if (fixed[i]) {
      EXPECT_EQ(ui.norm(), 0.0);
    } else {
      EXPECT_LT((ui - (B * (s.prone.V.row(i).transpose() - centre) + b)).norm(), 1e-12) << "vertex " << i;
    }
  }
}

TEST(Registration, LandmarkStepAloneHalvesTheTumourError) {
  const RegistrationResult r = register_scene(scene_with("steps: [rigid, landmarks]", "landmarks_only"));
  ASSERT_FALSE(r.steps.surface);
  for (const auto& t : r.tumours) EXPECT_LT(t.centroid_distance, 0.5 * t.rigid_centroid_distance) << t.name;
  EXPECT_LT(r.landmark_residual_max, 0.5e-3);
}

TEST(Registration, SurfaceStepAloneImprovesOnRigid) {
  const RegistrationResult r = register_scene(scene_with("steps: [surface]", "surface_only"), "accurate");
  ASSERT_FALSE(r.steps.landmarks);
  for (const auto& t : r.tumours) EXPECT_LT(t.centroid_distance, 0.5 * t.rigid_centroid_distance) << t.name;
  EXPECT_LT(r.skin_distance_mean, 0.1e-3);
}

TEST(Registration, FullMethodBringsEveryTumourWithinHalfAMillimetre) {
  const RegistrationResult r = register_scene(phantom_dir() + "/scene.yaml");
  ASSERT_EQ(r.tumours.size(), 5u);
  EXPECT_TRUE(r.converged);
  for (const auto& t : r.tumours) {
    EXPECT_LT(t.centroid_distance, 0.5e-3) << t.name;
    EXPECT_GT(t.rigid_centroid_distance, 1e-3) << t.name << ": the phantom should deform";
    EXPECT_NEAR(t.volume_ratio, 1.0, 0.02);
  }
}

class Misalignment : public ::testing::TestWithParam<std::string> {};

TEST_P(Misalignment, RigidAlignmentKeepsTheFullMethodWithinTwoMillimetres) {
  const RegistrationResult r = register_scene(scene_with("misalignment: " + GetParam(), "mis" + std::to_string(std::hash<std::string>{}(GetParam()))));
  EXPECT_TRUE(r.icp_used) << r.icp.message;
  EXPECT_LT(worst_error(r), 2e-3);
  EXPECT_LT(worst_error(r), 0.5e-3);  // in fact as good as without misalignment
}

INSTANTIATE_TEST_SUITE_P(Thesis525, Misalignment,
                         ::testing::Values("{rotation_deg: [15, 0, 0]}", "{rotation_deg: [0, 15, 0]}", "{rotation_deg: [0, 0, 15]}",
                                           "{translation_mm: [10, 0, 0]}", "{translation_mm: [0, 10, 0]}",
                                           "{translation_mm: [0, 0, -10]}", "{rotation_deg: [15, 15, 15], translation_mm: [10, 10, 10]}"));

TEST(Registration, WithoutTheRigidStepMisalignmentBreaksTheMethodAsInTheThesis) {
  const RegistrationResult r = register_scene(scene_with("misalignment: {rotation_deg: [15, 0, 0]}\nsteps: [landmarks, surface]", "mis_norigid"));
  EXPECT_GT(worst_error(r), 3e-3);
}

TEST(StepSelection, FollowsTheInputsAndNamesMissingFields) {
  const Scene full = load_meshed_scene(phantom_dir() + "/scene.yaml");
  PlannedSteps p = plan_steps(full);
  EXPECT_TRUE(p.rigid_landmarks && p.rigid_icp && p.landmarks && p.surface);
  EXPECT_FALSE(p.gravity);
  Scene lm = full;
  lm.supine_surface.reset();
  p = plan_steps(lm);
  EXPECT_TRUE(p.landmarks && !p.surface);
  Scene surf = full;
  surf.landmark_anchors.clear();
  surf.landmark_supine.resize(0, 3);
  p = plan_steps(surf);
  EXPECT_TRUE(p.surface && !p.landmarks && !p.rigid_landmarks && p.rigid_icp);
  Scene bad = lm;
  bad.steps = {"surface"};
  expect_throw_with<InputError>([&] { plan_steps(bad); }, "'surface' needs the field 'supine.surface'");
  Scene gravity = full;
  gravity.steps = {"gravity", "surface"};
  p = plan_steps(gravity);
  EXPECT_TRUE(p.gravity && p.surface && !p.landmarks && !p.rigid_landmarks);
  // unload: exactly when the scene gives the prone gravity, listed or not.
  EXPECT_FALSE(plan_steps(full).unload);
  Scene unload = full;
  unload.prone_gravity = Vec3(0, 0, 9.81);
  EXPECT_TRUE(plan_steps(unload).unload);
  unload.steps = {"landmarks", "surface"};
  EXPECT_TRUE(plan_steps(unload).unload);
  EXPECT_EQ(plan_steps(unload).describe(), "unload + landmarks + surface");
  // Rigid alignment alone reads neither the rest shape nor the material: no unload, no stiffness.
  unload.steps = {"rigid"};
  EXPECT_EQ(plan_steps(unload).describe(), "rigid (landmarks) + rigid (ICP)");
  EXPECT_FALSE(plan_simulates(unload));
  std::vector<std::string> rigid_warnings;
  const RegistrationModel rigid_model = prepare_model(unload, rigid_warnings);
  EXPECT_FALSE(rigid_model.unload.has_value());
  EXPECT_TRUE(run_registration(unload, rigid_model, preset_options("fast")).converged);
  unload.youngs_modulus_range = std::array<double, 2>{150, 24000};
  EXPECT_EQ(plan_steps(unload).describe(), "rigid (landmarks) + rigid (ICP)");
  EXPECT_TRUE(run_registration(unload, rigid_model, preset_options("fast")).converged);
  unload.steps = {"landmarks", "surface"};
  EXPECT_EQ(plan_steps(unload).describe(), "stiffness + unload + landmarks + surface");
  unload.youngs_modulus_range.reset();
  Scene listed = full;
  listed.steps = {"unload", "surface"};
  expect_throw_with<InputError>([&] { plan_steps(listed); }, "'unload' needs the field 'prone_gravity'");
  const std::string bad_path = scene_with("prone_gravity: [0, 0, 0]", "zero_prone_gravity");
  expect_throw_with<InputError>([&] { load_meshed_scene(bad_path); }, "prone_gravity");
  // A model prepared for another plan is refused, not silently used.
  std::vector<std::string> w;
  const RegistrationModel plain = prepare_model(full, w);
  expect_throw_with<InputError>([&] { run_registration(unload, plain, preset_options("fast")); }, "without the unload step");
}

// Issue 13: the unload may invert a quadratic forward model (material.unload_element_order); the
// registration steps stay linear. The coarse phantom's truth is linear, so the two rest shapes
// differ by the quadratic element's softer bending: a little, not nothing.
TEST(Unload, WithQuadraticElementsTheUnloadInvertsTheQuadraticModel) {
  Scene linear = btr::test::coarse_phantom_scene();
  linear.prone_gravity = Vec3(0, 0, 9.81);
  Scene quadratic = linear;
  quadratic.material.unload_element_order = ElementOrder::Quadratic;
  std::vector<std::string> w;
  const RegistrationModel ml = prepare_model(linear, w), mq = prepare_model(quadratic, w);
  ASSERT_TRUE(ml.unload && mq.unload);
  EXPECT_TRUE(mq.unload->converged) << mq.unload->stop_reason;
  EXPECT_LT(mq.unload->unload.mismatch, 1e-5);  // the quadratic model's prone shape is reproduced
  const double apart = (mq.rest.V - ml.rest.V).rowwise().norm().maxCoeff();
  std::printf("coarse phantom at 3400 Pa: the rest shape moved up to %.3f mm (linear) and %.3f mm (quadratic), %.3f mm "
              "apart\n", ml.unload->unload.rest_change * 1e3, mq.unload->unload.rest_change * 1e3, apart * 1e3);
  EXPECT_GT(apart, 0.01 * ml.unload->unload.rest_change);
  EXPECT_LT(apart, 0.5 * ml.unload->unload.rest_change);
  EXPECT_GT(mq.unload->unload.rest_change, ml.unload->unload.rest_change);  // quadratic elements bend more easily
  const RegistrationResult r = run_registration(quadratic, mq, preset_options("fast"));
  EXPECT_TRUE(r.converged) << btr::test::step_stops(r);
}

// The quadratic unload starts from the linear shape and has a budget of forward solves (the
// phantom's 400 Pa quadratic truth took 100 s over 11 continuation stages before it, and did not
// converge). Where it does not converge the linear shape stays, and its stop reason says so;
// where it does, it replaces the linear shape within the budget.
TEST(Unload, AQuadraticPassThatDoesNotConvergeLeavesTheLinearShape) {
  Scene s = btr::test::coarse_phantom_scene();
  s.material.unload_element_order = ElementOrder::Quadratic;
  std::vector<std::string> w;
  const RegistrationModel m = prepare_model(s, w);  // not unloaded: no prone_gravity
  ASSERT_EQ(m.material.unload_element_order, ElementOrder::Quadratic);
  const TetMesh loaded{m.prone, m.rest.T};
  const Vec3 g(0, 0, 9.81);
  const UnloadResult linear = estimate_unloaded_shape(unload_problem(m, loaded, g), UnloadOptions{});
  ASSERT_TRUE(linear.converged) << linear.stop_reason;

  UnloadOptions starved;  // one forward solve and no continuation: it cannot get there
  starved.max_iterations = 1;
  starved.max_stages = 0;
  UnloadResult kept = linear;
  refine_with_model_elements(m, loaded, g, starved, kept);
  EXPECT_TRUE(kept.converged);
  EXPECT_EQ(kept.elements, ElementOrder::Linear);  // the linear region differentiates the linear unload then
  EXPECT_EQ((kept.rest - linear.rest).cwiseAbs().maxCoeff(), 0.0);
  EXPECT_NE(kept.stop_reason.find("with quadratic elements it did not converge"), std::string::npos) << kept.stop_reason;
  EXPECT_NE(kept.stop_reason.find("so the linear shape is used"), std::string::npos) << kept.stop_reason;
  EXPECT_GE(kept.seconds, linear.seconds);  // the attempt's time counts

  UnloadResult refined = linear;
  refine_with_model_elements(m, loaded, g, UnloadOptions{}, refined);
  EXPECT_TRUE(refined.converged) << refined.stop_reason;
  EXPECT_EQ(refined.elements, ElementOrder::Quadratic);
  EXPECT_EQ(unload_report(refined, m.prone).unload.elements, ElementOrder::Quadratic);
  EXPECT_NE(refined.stop_reason.find("(quadratic elements, from the linear shape)"), std::string::npos) << refined.stop_reason;
  EXPECT_LE(refined.iterations, kModelElementsForwardSolves);
  EXPECT_GT((refined.rest - linear.rest).rowwise().norm().maxCoeff(), 1e-6);

  Scene told_linear = s;  // nothing to do with linear elements
  told_linear.material.unload_element_order = ElementOrder::Linear;
  UnloadResult same = linear;
  refine_with_model_elements(prepare_model(told_linear, w), loaded, g, UnloadOptions{}, same);
  EXPECT_EQ(same.stop_reason, linear.stop_reason);
  EXPECT_EQ((same.rest - linear.rest).cwiseAbs().maxCoeff(), 0.0);
}

// With E estimated the search compares its candidates with linear elements and unloads the
// chosen one with quadratic ones: the same E, another rest shape, the report naming the elements.
TEST(Stiffness, WithQuadraticUnloadTheChosenEIsUnloadedWithQuadraticElements) {
  const std::string d = soft_phantom_dir("phantom12_soft_e");
  const std::string estimate = "material: {youngs_modulus: estimate}\nprone_gravity: [0, 0, 9.81]";
  const std::string quadratic = "material: {youngs_modulus: estimate, unload_element_order: quadratic}\nprone_gravity: [0, 0, 9.81]";
  const RegistrationResult rl = register_scene(scene_with(estimate, "estimate_linear", d), preset_options("fast"));
  const RegistrationResult rq = register_scene(scene_with(quadratic, "estimate_quadratic", d), preset_options("fast"));
  ASSERT_GE(rq.reports.size(), 2u);
  EXPECT_EQ(rq.reports[1].name, "unload");
  EXPECT_TRUE(rq.reports[1].converged) << rq.reports[1].stop_reason;
  EXPECT_NE(rq.reports[1].stop_reason.find("(quadratic elements, from the linear shape)"), std::string::npos)
      << rq.reports[1].stop_reason;
  EXPECT_EQ(rq.estimated_youngs_modulus, rl.estimated_youngs_modulus);
  EXPECT_NE(rq.reports[1].unload.rest_change, rl.reports[1].unload.rest_change);
  std::printf("600 Pa phantom, E estimated %.0f Pa: rest shape moved %.2f mm (linear unload), %.2f mm (quadratic); worst "
              "tumour %.3f / %.3f mm\n", rq.estimated_youngs_modulus, rl.reports[1].unload.rest_change * 1e3,
              rq.reports[1].unload.rest_change * 1e3, worst_error(rl) * 1e3, worst_error(rq) * 1e3);
  EXPECT_TRUE(rq.converged) << btr::test::step_stops(rq);
}

// Issue 13: the unloaded shape needs the right stiffness. The method told 3400 Pa on a 600 Pa
// breast, asked to estimate it: the estimate lands near the truth, the tumours within half a
// millimetre; a range that excludes the truth is reported as a bound, not as converged.
TEST(Stiffness, EstimatedFromTheLandmarksItFindsTheSoftBreast) {
  const std::string d = soft_phantom_dir("phantom12_soft_e");
  const std::string estimate = "material: {youngs_modulus: estimate}\nprone_gravity: [0, 0, 9.81]";
  RegistrationOptions with_region = preset_options("balanced");
  with_region.uncertainty.enabled = true;  // the linearised region, to see it take the estimate's spread
  const RegistrationResult r = register_scene(scene_with(estimate, "estimate", d), with_region);
  ASSERT_GE(r.reports.size(), 2u);
  EXPECT_EQ(r.reports[0].name, "stiffness");
  EXPECT_EQ(r.reports[1].name, "unload");
  EXPECT_EQ(r.steps.describe(), "stiffness + unload + rigid (landmarks) + rigid (ICP) + landmarks + surface");
  std::printf("600 Pa phantom, method told to estimate: E = %.0f Pa after %zu candidates (%s, %.1f s), worst tumour %.3f mm\n",
              r.estimated_youngs_modulus, r.stiffness_evaluations.size(), r.reports[0].stop_reason.c_str(),
              r.reports[0].seconds, worst_error(r) * 1e3);
  EXPECT_TRUE(r.reports[0].converged) << r.reports[0].stop_reason;
  // The candidates are unloaded to 0.1 mm; the chosen one is finished to the unload's own 0.01.
  EXPECT_TRUE(r.reports[1].converged) << r.reports[1].stop_reason;
  EXPECT_NE(r.reports[1].stop_reason.find("within 0.010 mm"), std::string::npos) << r.reports[1].stop_reason;
  EXPECT_NEAR(r.estimated_youngs_modulus, 600, 60);
  EXPECT_LT(worst_error(r), 0.5e-3);
  EXPECT_TRUE(r.converged);
  // The grid walk (8 log-spaced points over the default 150 to 24000 Pa from the stiff end, and
  // before the softest the point halfway to it where the last three put a parabola's minimum
  // before it) stops at its first candidate past the minimum: a halfway point above the best, or
  // a grid point above 1.5x it. None before it is past 1.5x the best (that bracket is all the refinement
  // needs; a softer candidate would be the search's costliest). The refinement comes after, its
  // candidates inside the bracket, so the walk is the evaluations while E falls.
  {
    const StiffnessOptions so;
    const auto& ev = r.stiffness_evaluations;
    size_t walk = 1;
    while (walk < ev.size() && ev[walk].youngs_modulus < ev[walk - 1].youngs_modulus) ++walk;
    ASSERT_GE(walk, 3u);
    double best = ev[0].misfit;
    for (size_t i = 1; i + 1 < walk; ++i) {
      EXPECT_LE(ev[i].misfit, 1.5 * best) << "the walk went on past a candidate 1.5x the best at " << ev[i].youngs_modulus << " Pa";
      best = std::min(best, ev[i].misfit);
    }
    const double last = ev[walk - 1].youngs_modulus;
    const bool on_grid = on_stiffness_grid(std::log(last), stiffness_grid(so.min_youngs_modulus, so.max_youngs_modulus, so.grid_points));
    EXPECT_GT(ev[walk - 1].misfit, (on_grid ? 1.5 : 1.0) * best) << "the walk stopped at " << last << " Pa";
    for (size_t i = walk; i < ev.size(); ++i) EXPECT_GT(ev[i].youngs_modulus, last) << "a refinement candidate outside the bracket";
  }
  // Issue 14: the estimate's own spread (1.5 mm landmarks) replaces the range's in the region:
  // far narrower than the range's sd of ln E (0.78 for 200 to 3000 Pa), and it holds the truth.
  const double sd = r.estimated_youngs_modulus_log_sd;
  std::printf("  sd of ln E from the landmarks %.3f (ln(E / 600 Pa) %+.3f)\n", sd, std::log(r.estimated_youngs_modulus / 600));
  EXPECT_GT(sd, 0.0);
  EXPECT_LT(sd, 0.3);
  EXPECT_LT(std::abs(std::log(r.estimated_youngs_modulus / 600)), 3 * sd);
  EXPECT_NE(r.uncertainty_note.find("E as estimated from the landmarks"), std::string::npos) << r.uncertainty_note;
  for (const TumourResult& t : r.tumours) {
    ASSERT_TRUE(t.uncertainty.has_value());
    const Vec3& dE = t.uncertainty->d_log_youngs_modulus;
    EXPECT_NEAR(t.uncertainty->sources[0].second.trace(), sd * sd * dE.squaredNorm(), 1e-12 + 1e-9 * dE.squaredNorm()) << t.name;
  }

  // A range above the truth: the stiff end's bound, said so, and not converged.
  const RegistrationResult b =
      register_scene(scene_with("material: {youngs_modulus: estimate, youngs_modulus_range: [2000, 24000]}\n"
                                "prone_gravity: [0, 0, 9.81]", "estimate_bound", d));
  EXPECT_FALSE(b.reports[0].converged);
  EXPECT_NE(b.reports[0].stop_reason.find("end of the range"), std::string::npos) << b.reports[0].stop_reason;
  EXPECT_NEAR(b.estimated_youngs_modulus, 2000, 1);
  EXPECT_FALSE(b.converged);

  // What the step needs is named.
  Scene s = load_meshed_scene(scene_with(estimate, "estimate", d));
  Scene no_gravity = s;
  no_gravity.prone_gravity.reset();
  expect_throw_with<InputError>([&] { plan_steps(no_gravity); }, "'estimate' needs the field 'prone_gravity'");
  Scene few = s;
  few.landmark_anchors.resize(2);
  few.landmark_supine.conservativeResize(2, 3);
  expect_throw_with<InputError>([&] { plan_steps(few); }, "needs >= 3 landmarks");
  expect_throw_with<InputError>(
      [&] { load_meshed_scene(scene_with("material: {youngs_modulus: 600, youngs_modulus_range: [100, 1000]}", "range_only", d)); },
      "only with 'youngs_modulus: estimate'");
}

// Issue 14: how well the landmarks fix E. Gauss-Newton: sd(ln E) = sigma / |dr/d ln E|, sigma
// the landmarks' sd, or the misfit per residual degree of freedom (3n - 7) where larger.
// A candidate's unload gets a budget of forward solves: max(minimum, factor x the most a
// simulated candidate took so far). Past it the candidate is one that cannot be simulated, and
// says why; before the first candidate it stops, the search is the unbudgeted one. Here a
// factor of 1 makes it bind on the 600 Pa phantom, whose softer candidates need more solves.
TEST(Stiffness, ACandidateOverItsForwardSolveBudgetIsNotSimulatedAndSaysWhy) {
  const Scene s = load_meshed_scene(
      scene_with("material: {youngs_modulus: estimate}\nprone_gravity: [0, 0, 9.81]", "estimate_budget", soft_phantom_dir("phantom12_soft_budget")));
  std::vector<std::string> w;
  const RegistrationModel m = prepare_model(s, w);
  StiffnessOptions so;
  const StiffnessEstimate free = estimate_stiffness(m, *s.prone_gravity, s.landmark_anchors, s.landmark_supine, so);
  so.candidate_budget_factor = 1;
  so.min_candidate_forward_solves = 3;
  StiffnessEstimate tight;
  try {
    tight = estimate_stiffness(m, *s.prone_gravity, s.landmark_anchors, s.landmark_supine, so);
  } catch (const SolverError& e) {  // every candidate over the budget: a search with nothing to compare
    FAIL() << e.what();
  }
  auto print = [](const char* name, const StiffnessEstimate& e) {
    std::printf("%s: E %.0f Pa (%s)\n", name, e.youngs_modulus, e.stop_reason.c_str());
    for (const auto& c : e.evaluations)
      std::printf("  %7.1f Pa: misfit %.3f mm, %d forward solves %s\n", c.youngs_modulus, c.misfit * 1e3, c.forward_solves, c.failure.c_str());
  };
  print("no factor", free);
  print("factor 1", tight);
  int most = 0, stopped = 0;
  bool diverged = false;
  for (size_t i = 0; i < tight.evaluations.size(); ++i) {
    const StiffnessCandidate& c = tight.evaluations[i];
    const int budget = std::max(so.min_candidate_forward_solves, most);
    EXPECT_EQ(std::isfinite(c.misfit), c.failure.empty()) << c.youngs_modulus << " Pa";
    if (c.failure.find("forward-solve budget (" + std::to_string(budget) + ") spent") != std::string::npos) {
      EXPECT_EQ(c.forward_solves, budget);  // its unload spent it; no supine solve
      ++stopped;
      diverged = true;
    } else {
      EXPECT_LE(c.forward_solves, budget + 1) << c.youngs_modulus << " Pa";  // the unload's and the supine solve
      if (!diverged) {
        ASSERT_LT(i, free.evaluations.size());
        EXPECT_EQ(c.youngs_modulus, free.evaluations[i].youngs_modulus);
        EXPECT_EQ(c.misfit, free.evaluations[i].misfit);
        EXPECT_EQ(c.forward_solves, free.evaluations[i].forward_solves);
      }
    }
    if (c.failure.empty()) most = std::max(most, c.forward_solves);
  }
  EXPECT_GE(stopped, 1) << "the test needs a candidate over its budget";
  so.candidate_budget_factor = -1;
  EXPECT_THROW(estimate_stiffness(m, *s.prone_gravity, s.landmark_anchors, s.landmark_supine, so), InputError);
}

TEST(Stiffness, TheEstimatesSpreadIsTheLandmarkNoiseOverTheMisfitsSlope) {
  StiffnessEstimate e;
  e.landmarks = 5;                 // 8 residual degrees of freedom
  e.landmark_sensitivity = 0.02;   // 20 mm of landmark residual per unit ln E
  e.misfit = 0.0005;               // 0.5 mm RMS: 5 * 0.25 / 8 mm^2 per coordinate, under 1.5^2
  EXPECT_NEAR(e.log_sd(0.0015), 0.0015 / 0.02, 1e-12);
  e.misfit = 0.004;                // 4 mm RMS: the model misses the landmarks by more than their noise
  EXPECT_NEAR(e.log_sd(0.0015), std::sqrt(5 * 0.004 * 0.004 / 8) / 0.02, 1e-12);
  EXPECT_NEAR(e.log_sd(0), std::sqrt(5 * 0.004 * 0.004 / 8) / 0.02, 1e-12);
  e.at_bound = true;               // a bound is not an estimate with a spread
  EXPECT_EQ(e.log_sd(0.0015), 0);
  e.at_bound = false;
  e.landmark_sensitivity = 0;      // no neighbour simulated
  EXPECT_EQ(e.log_sd(0.0015), 0);
}

// Issue 10: with face normals the point-to-plane springs jump wherever a skin vertex's closest
// point crosses an edge of the supine mesh, so on soft tissue the alternation ended jittering at
// about the balanced tolerance (0.1 mm per projection) and stalled. Vertex normals blended at
// the closest point move the springs continuously: the alternation contracts to its fixed
// point. On a soft phantom told its E and prone gravity that limit is the truth.
TEST(SurfaceStep, InterpolatedNormalsContractToTheFixedPointOnASoftBreast) {
  const std::string d = soft_phantom_dir("phantom12_soft_normals");
  const Scene s = load_meshed_scene(scene_with("material: {youngs_modulus: 600, poisson_ratio: 0.49, density: 1000}\n"
                                        "prone_gravity: [0, 0, 9.81]",
                                        "soft_told", d));
  std::vector<std::string> warnings;
  const RegistrationModel m = prepare_model(s, warnings);
  std::map<MeshNormals, RegistrationResult> r;
  for (const MeshNormals n : {MeshNormals::Face, MeshNormals::Interpolated}) {
    RegistrationOptions o = preset_options("balanced");
    o.surface.target_normals = n;
    o.surface.sliding = SkinSliding::Free;  // the thesis's alternation, which the normals change
    r[n] = run_registration(s, m, o);
  }
  const RegistrationResult& smooth = r[MeshNormals::Interpolated];
  const StepReport& surface = smooth.reports.back();
  ASSERT_EQ(surface.name.rfind("surface", 0), 0u) << step_stops(smooth);
  EXPECT_TRUE(surface.converged) << step_stops(smooth);
  // Contracting: after the first two projections (the landmark step's state relaxing) the
  // skin moves less at every projection.
  const std::vector<double>& res = surface.projection_residuals;
  ASSERT_GE(res.size(), 3u);
  for (size_t k = 3; k < res.size(); ++k) EXPECT_LE(res[k], res[k - 1] * (1 + 1e-6)) << "projection " << k + 1;
  const double face = worst_error(r[MeshNormals::Face]), blended = worst_error(smooth);
  std::printf("600 Pa phantom told its E and gravity: worst tumour %.3f mm with face normals (%s), %.3f mm interpolated "
              "(%zu projections)\n",
              face * 1e3, r[MeshNormals::Face].converged ? "converged" : "not converged", blended * 1e3, res.size());
  // Both normals leave the truth a fixed point; on this 12 mm mesh the two limits differ by
  // hundredths of a millimetre (0.050 and 0.071 mm measured).
  EXPECT_LT(std::abs(blended - face), 0.05e-3);
  EXPECT_LT(blended, 0.15e-3);
}

// Issue 13: with the prone gravity given, the model's rest shape is the unloaded shape. On a
// soft phantom (truth: our FEM at 600 Pa, the method told the same E) the full method already
// hides most of the prone-as-rest error behind the surface; with landmarks alone it shows, and
// unloading removes it.
TEST(Unload, InThePipelineItBeatsTheProneShapeAsRestOnASoftBreast) {
  const std::string d = soft_phantom_dir("phantom12_soft");
  const std::string material = "material: {youngs_modulus: 600, poisson_ratio: 0.49, density: 1000}\n";
  for (const std::string steps : {"auto", "[rigid, landmarks]"}) {
    const std::string name = steps == "auto" ? "full" : "landmarks";
    const RegistrationResult prone = register_scene(scene_with(material + "steps: " + steps, "soft_" + name, d));
    const RegistrationResult unloaded =
        register_scene(scene_with(material + "steps: " + steps + "\nprone_gravity: [0, 0, 9.81]", "soft_unload_" + name, d));
    ASSERT_FALSE(unloaded.reports.empty());
    const StepReport& u = unloaded.reports.front();
    EXPECT_EQ(u.name, "unload");
    EXPECT_TRUE(u.converged) << u.stop_reason;
    EXPECT_LT(u.unload.mismatch, 1e-4);
    EXPECT_GT(u.unload.rest_change, 0.005);
    std::printf("600 Pa phantom, %s: worst tumour %.3f mm with the prone shape as rest, %.3f mm unloaded (rest moved "
                "%.1f mm, %d forward solves, %.2f s)\n",
                name.c_str(), worst_error(prone) * 1e3, worst_error(unloaded) * 1e3, u.unload.rest_change * 1e3,
                u.outer_iterations, u.seconds);
    EXPECT_LT(worst_error(unloaded), worst_error(prone));
    if (name == "full") {
      EXPECT_LT(worst_error(unloaded), 0.5e-3);
    } else {  // 3.8 -> 0.73 mm when written
      EXPECT_LT(worst_error(unloaded), 0.3 * worst_error(prone));
    }
  }
}

// A registration with the nodal volume term that ends not converged because the mesh folded
// says what holds such meshes together (the measured alternatives); nothing otherwise.
TEST(FoldAdvice, NamesTheMeasuredAlternativesOnlyForANodalFold) {
  RegistrationModel model;
  model.volume_form = VolumeForm::Nodal;
  StepReport fine, folded, capped;
  fine.name = folded.name = capped.name = "surface";
  fine.converged = true;
  folded.stop_reason = "the skin settled, but 40 tetrahedra ended inverted (40 new, beyond the allowance of 14): the mesh folded";
  capped.stop_reason = "projection cap (150) reached";
  EXPECT_EQ(fold_advice(model, {fine}), "");
  EXPECT_EQ(fold_advice(model, {capped}), "");
  EXPECT_NE(fold_advice(model, {fine, folded}).find("material.nodal_element_share: 5"), std::string::npos);
  StepReport inverted_landmarks;  // Newton's own fold stop keeps the last uninverted state (none inverted)
  inverted_landmarks.stop_reason = "stalled: every step inverted an element, and letting them invert folded the mesh";
  EXPECT_NE(fold_advice(model, {inverted_landmarks}).find("nodal_element_share"), std::string::npos);
  model.material.nodal_element_share = 5;
  const std::string with_share = fold_advice(model, {folded});
  EXPECT_NE(with_share.find("volume_form: element"), std::string::npos);
  EXPECT_EQ(with_share.find("nodal_element_share: 5"), std::string::npos);
  model.volume_form = VolumeForm::Element;
  EXPECT_EQ(fold_advice(model, {folded}), "");
}

TEST(SceneErrors, NameTheFieldAtFault) {
  const std::string d = btr::test::temp_dir();
  btr::test::write_text(d + "/a.yaml", "units: mm\n");
  expect_throw_with<InputError>([&] { load_meshed_scene(d + "/a.yaml"); }, "field 'prone'");
  expect_throw_with<InputError>([&] { load_meshed_scene(d + "/missing.yaml"); }, "cannot open scene");
  btr::test::write_text(d + "/b.yaml", "units: [\n");
  expect_throw_with<InputError>([&] { load_meshed_scene(d + "/b.yaml"); }, "YAML syntax error");
  expect_throw_with<InputError>([&] { load_meshed_scene(scene_with("units: furlong", "bad_units")); }, "field 'units'");
  expect_throw_with<InputError>([&] { load_meshed_scene(scene_with("steps: [rigid, teleport]", "bad_step")); }, "unknown step 'teleport'");
  expect_throw_with<InputError>([&] { load_meshed_scene(scene_with("preset: turbo", "bad_preset")); }, "field 'preset'");
  expect_throw_with<InputError>([&] { load_meshed_scene(scene_with("material: {youngs_modulus: -5}", "bad_E")); }, "field 'material'");
  expect_throw_with<InputError>([&] { load_meshed_scene(scene_with("chest_wall: nowhere.txt", "bad_wall")); }, "field 'chest_wall'");
  expect_throw_with<InputError>(
      [&] { load_meshed_scene(scene_with("material: {volume_form: nodal, nodal_element_share: -1}", "bad_share")); },
      "field 'material.nodal_element_share': must be >= 0");
  EXPECT_EQ(load_meshed_scene(scene_with("material: {volume_form: nodal, nodal_element_share: 5}", "share")).material.nodal_element_share, 5);
  EXPECT_TRUE(load_meshed_scene(scene_with("material: {volume_form: nodal}", "fallback")).nodal_fallback);
  EXPECT_FALSE(load_meshed_scene(scene_with("material: {volume_form: nodal, nodal_fallback: false}", "no_fallback")).nodal_fallback);
  expect_throw_with<InputError>([&] { load_meshed_scene(scene_with("material: {nodal_fallback: sometimes}", "bad_fallback")); },
                                "field 'material.nodal_fallback'");
  EXPECT_EQ(load_meshed_scene(scene_with("material: {unload_element_order: quadratic}", "quadratic")).material.unload_element_order,
            ElementOrder::Quadratic);
  expect_throw_with<InputError>([&] { load_meshed_scene(scene_with("material: {unload_element_order: cubic}", "cubic")); },
                                "field 'material.unload_element_order': element order must be 'linear' or 'quadratic'");
  btr::test::write_text(phantom_dir() + "/bad_landmarks.csv", "prone_index,supine_index\n99999,1\n");
  expect_throw_with<InputError>([&] { load_meshed_scene(scene_with("landmarks: bad_landmarks.csv", "bad_lm")); }, "field 'landmarks'");
}

// Issue 10: inputs say what they mean. Unknown and misplaced keys name the nearest valid one,
// wrong types name the field, units and gravity must be stated, and a metre mesh read as
// millimetres is called a units mistake (btr_register maps every InputError to exit code 2).
TEST(SceneErrors, KeysTypesUnitsAndGravityAreChecked) {
  expect_throw_with<InputError>([&] { load_meshed_scene(scene_with("cell_size_mm: 5", "misplaced")); },
                                "field 'cell_size_mm': unknown key (did you mean prone.cell_size_mm?)");
  expect_throw_with<InputError>([&] { load_meshed_scene(scene_with("prone: {tetmesh: prone.vtk}", "misspelt")); },
                                "field 'prone.tetmesh': unknown key (did you mean prone.tet_mesh?)");
  expect_throw_with<InputError>([&] { load_meshed_scene(scene_with("units: [mm]", "units_list")); },
                                "field 'units': expected a single value");
  expect_throw_with<InputError>([&] { load_meshed_scene(scene_with("material: {youngs_modulus: soft}", "E_text")); },
                                "field 'material.youngs_modulus': expected a number, got 'soft'");
  expect_throw_with<InputError>([&] { load_meshed_scene(scene_with("preset: {name: fast}", "preset_map")); },
                                "field 'preset': expected a single value");
  expect_throw_with<InputError>([&] { load_meshed_scene(scene_with("tumours: [top]", "tumour_text")); },
                                "field 'tumours[0]': expected a mapping");
  expect_throw_with<InputError>([&] { load_meshed_scene(scene_with("units: m", "metre_units")); }, "is `units` right (mm or m)?");
  expect_throw_with<InputError>([&] { load_meshed_scene(scene_with("gravity: [0, 0, 0]", "zero_g")); }, "field 'gravity': must not be zero");
  // Without `units` or `gravity` at all.
  auto without = [&](const std::string& key, const std::string& name) {
    btr::test::write_text(phantom_dir() + "/" + name + ".yaml", without_key(phantom_scene_text(), key));
    return phantom_dir() + "/" + name + ".yaml";
  };
  expect_throw_with<InputError>([&] { load_meshed_scene(without("units", "no_units")); }, "field 'units': missing");
  expect_throw_with<InputError>([&] { load_meshed_scene(without("gravity", "no_gravity")); }, "field 'gravity': missing");
}

// prone.tumour_cell_size_mm: where a call meshes the prone model (here re-meshes the phantom's
// tetrahedra at 12 mm), each tumour's bounding ball gets finer cells; a bad value names the field.
TEST(SceneFromSurface, TumourCellSizeRefinesTheSimulationMeshAroundEachTumour) {
  const Scene plain = load_meshed_scene(phantom_dir() + "/scene.yaml");
  const Scene stated = load_meshed_scene(scene_with("prone: {tet_mesh: prone.vtk, tumour_cell_size_mm: 5}", "tumour_cells"));
  EXPECT_DOUBLE_EQ(stated.tumour_cell_size.value_or(-1), 0.005);
  EXPECT_FALSE(plain.tumour_cell_size.has_value());  // the preset's (accurate: 4 mm; the others none)
  const Scene none = load_meshed_scene(scene_with("prone: {tet_mesh: prone.vtk, tumour_cell_size_mm: 0}", "no_tumour_cells"));
  EXPECT_EQ(none.tumour_cell_size.value_or(-1), 0.0);
  const RegistrationOptions accurate = preset_options("accurate");
  EXPECT_EQ(tumour_cell_size_for(plain, accurate), 0.004);
  EXPECT_EQ(tumour_cell_size_for(plain, preset_options("balanced")), 0.0);
  EXPECT_EQ(tumour_cell_size_for(plain, preset_options("fast")), 0.0);
  EXPECT_EQ(tumour_cell_size_for(stated, accurate), 0.005);  // the scene's, stated, wins
  EXPECT_EQ(tumour_cell_size_for(none, accurate), 0.0);
  expect_throw_with<InputError>([&] { load_meshed_scene(scene_with("prone: {tet_mesh: prone.vtk, tumour_cell_size_mm: -2}", "bad_cells")); },
                                "field 'prone.tumour_cell_size_mm': must be 0 (none) or a positive size");
  const Scene a = with_simulation_mesh(plain, 0.012, 0), b = with_simulation_mesh(stated, 0.012, 0.005);
  EXPECT_EQ(tumour_refinements(plain, 0.012, 0).size(), 0u);
  ASSERT_EQ(tumour_refinements(stated, 0.012, 0.005).size(), stated.tumours.size());
  EXPECT_EQ(tumour_refinements(stated, 0.004, 0.005).size(), 0u);  // not below the mesh's own size: nothing to refine
  // The mean volume of the tetrahedra holding the tumours' vertices.
  auto tumour_cell_volume = [&](const Scene& m) {
    double v = 0;
    long n = 0;
    for (const auto& t : m.tumours) {
      const Embedding e = embed_points(m.prone, t.prone.V);
      for (Eigen::Index i = 0; i < e.tet.size(); ++i, ++n) v += std::abs(tet_signed_volume(m.prone.V, m.prone.T, e.tet[i]));
    }
    return v / static_cast<double>(n);
  };
  std::printf("tumour cells: %.0f mm^3 at 12 mm, %.0f mm^3 with 5 mm around the tumours; %ld -> %ld tetrahedra\n",
              tumour_cell_volume(a) * 1e9, tumour_cell_volume(b) * 1e9, static_cast<long>(a.prone.T.rows()),
              static_cast<long>(b.prone.T.rows()));
  EXPECT_LT(tumour_cell_volume(b), 0.25 * tumour_cell_volume(a));
  EXPECT_GT(b.prone.T.rows(), a.prone.T.rows());
  EXPECT_EQ(b.chest_wall.size() > 0, true);
  EXPECT_EQ(b.landmark_anchors.size(), plain.landmark_anchors.size());
  // Finer around its tumours, not elsewhere: a call at 12 mm does not mesh it again.
  RegistrationOptions at12 = preset_options("balanced");
  at12.simulation_cell_size = 0.012;
  EXPECT_LT(mean_edge_length(b.prone), 1.1 * 0.012);
  EXPECT_FALSE(needs_simulation_mesh(b, at12));
  EXPECT_FALSE(needs_simulation_mesh(a, at12));
  // Cells too fine for the memory budget: refused before meshing, naming where the size came from.
  expect_throw_with<InputError>([&] { with_simulation_mesh(plain, 0.012, 1e-5); },
                                "refinement balls are the tumours', at 0.01 mm: prone.tumour_cell_size_mm, else the preset's");
}

TEST(SceneFromSurface, TetrahedralizesAndReattachesChestWallAndLandmarks) {
  // The prone model given as a surface: indices refer to the surface and must survive meshing.
  const Scene tets = load_meshed_scene(phantom_dir() + "/scene.yaml");
  const std::string d = phantom_dir();
  SurfaceMesh skin;
  std::vector<int> to_tet;
  skin = boundary_surface(tets.prone, &to_tet);
  write_surface(d + "/prone_skin_surface.obj", skin, LengthUnit::Millimetre);
  std::vector<int> wall;
  for (size_t i = 0; i < to_tet.size(); ++i)
    if (std::find(tets.chest_wall.begin(), tets.chest_wall.end(), to_tet[i]) != tets.chest_wall.end()) wall.push_back(static_cast<int>(i));
  write_index_list(d + "/chest_wall_surface.txt", wall);
  std::vector<LandmarkPair> pairs;
  for (Eigen::Index i = 0; i < tets.landmark_supine.rows(); ++i) {
    LandmarkPair p;
    p.prone_vertex = static_cast<int>(std::find(to_tet.begin(), to_tet.end(), tets.landmark_anchors[i].v[0]) - to_tet.begin());
    p.supine_point = tets.landmark_supine.row(i).transpose();
    pairs.push_back(p);
  }
  write_landmark_pairs(d + "/landmarks_surface.csv", pairs, LengthUnit::Millimetre);
  const std::string path = scene_with(
      "prone: {surface: prone_skin_surface.obj, cell_size_mm: 12}\nchest_wall: chest_wall_surface.txt\nlandmarks: landmarks_surface.csv",
      "from_surface");
  const Scene s = load_meshed_scene(path);
  EXPECT_TRUE(s.tetrahedralized);
  for (int v : s.chest_wall) EXPECT_LT(std::abs(s.prone.V(v, 2)), 1e-6);
  for (size_t i = 0; i < s.landmark_anchors.size(); ++i)
    EXPECT_LT((s.landmark_anchors[i].position(s.prone.V) - tets.landmark_anchors[i].position(tets.prone.V)).norm(), 1.2e-3);
  const RegistrationResult r = register_scene(path);
  EXPECT_LT(worst_error(r), 0.5e-3);

  // Meshed once (issue 10): loaded without meshing, then meshed by the caller at the size it
  // simulates, after which the preset sees no finer mesh to coarsen.
  Scene l = load_scene(path);
  EXPECT_FALSE(l.tetrahedralized);
  EXPECT_EQ(l.prone.T.rows(), 0);
  ASSERT_TRUE(l.prone_source.has_value());
  EXPECT_EQ(l.prone_source->cell_size.value_or(0), 0.012);
  RegistrationOptions at12 = preset_options("balanced");
  at12.simulation_cell_size = 0.012;
  // Its simulation scene is the surface meshed at that size (before, the empty model's boundary
  // went to CGAL, which crashed on it).
  const std::optional<Scene> meshed_for_simulation = simulation_scene(l, at12);
  ASSERT_TRUE(meshed_for_simulation.has_value());
  EXPECT_TRUE(meshed_for_simulation->tetrahedralized);
  EXPECT_NEAR(static_cast<double>(meshed_for_simulation->prone.T.rows()), static_cast<double>(s.prone.T.rows()),
              0.02 * s.prone.T.rows());
  EXPECT_EQ(meshed_for_simulation->landmark_anchors.size(), s.landmark_anchors.size());
  // A size in millimetres is the preset's size in metres to the bit: 9 * 1e-3 is not 0.009, and
  // CGAL meshed other tetrahedra for it than for the balanced preset's nodal 9 mm.
  const Scene nine = load_scene(scene_with(
      "prone: {surface: prone_skin_surface.obj, cell_size_mm: 9}\nchest_wall: chest_wall_surface.txt\nlandmarks: landmarks_surface.csv",
      "nine_mm"));
  ASSERT_TRUE(nine.prone_source.has_value());
  EXPECT_EQ(nine.prone_source->cell_size.value_or(0), preset_options("balanced").nodal_simulation_cell_size);
  mesh_prone(l, 0.012, 0);
  EXPECT_TRUE(l.tetrahedralized);
  EXPECT_NEAR(static_cast<double>(l.prone.T.rows()), static_cast<double>(s.prone.T.rows()), 0.02 * s.prone.T.rows());
  EXPECT_EQ(l.landmark_anchors.size(), s.landmark_anchors.size());
  EXPECT_FALSE(simulation_scene(l, at12).has_value());

  // The same surface as a modelling tool may export it: every 7th face flipped, and then the
  // whole surface inside out. Both are repaired with a warning that gives the count.
  SurfaceMesh flipped = skin;
  long n_flipped = 0;
  for (Eigen::Index f = 0; f < flipped.F.rows(); f += 7, ++n_flipped) flipped.F.row(f) = Eigen::RowVector3i(flipped.F(f, 0), flipped.F(f, 2), flipped.F(f, 1));
  write_surface(d + "/prone_flipped.obj", flipped, LengthUnit::Millimetre);
  const Scene fs = load_meshed_scene(scene_with(
      "prone: {surface: prone_flipped.obj, cell_size_mm: 12}\nchest_wall: chest_wall_surface.txt\nlandmarks: landmarks_surface.csv",
      "from_flipped"));
  ASSERT_EQ(fs.warnings.size(), 1u);
  EXPECT_NE(fs.warnings[0].find("prone.surface: " + std::to_string(n_flipped) + " of " + std::to_string(skin.F.rows()) + " faces"),
            std::string::npos) << fs.warnings[0];
  EXPECT_EQ(fs.prone.T.rows() > 0, true);
  SurfaceMesh inside_out = skin;
  inside_out.F.col(1).swap(inside_out.F.col(2));
  write_surface(d + "/prone_inside_out.obj", inside_out, LengthUnit::Millimetre);
  const Scene io = load_meshed_scene(scene_with(
      "prone: {surface: prone_inside_out.obj, cell_size_mm: 12}\nchest_wall: chest_wall_surface.txt\nlandmarks: landmarks_surface.csv",
      "from_inside_out"));
  ASSERT_EQ(io.warnings.size(), 1u);
  EXPECT_NE(io.warnings[0].find(std::to_string(skin.F.rows()) + " of " + std::to_string(skin.F.rows())), std::string::npos);
}

TEST(Outputs, ReportAndPictureAreWritten) {
  const Scene s = load_meshed_scene(phantom_dir() + "/scene.yaml");
  std::vector<std::string> w;
  const RegistrationModel m = prepare_model(s, w);
  const RegistrationResult r = run_registration(s, m, preset_options("fast"));
  const std::string d = btr::test::temp_dir();
  const auto files = write_registration_outputs(d, s, m, r, 0.1);
  EXPECT_TRUE(std::filesystem::exists(d + "/report.json"));
  EXPECT_GT(std::filesystem::file_size(d + "/cross_section.png"), 1000u);
  std::ifstream png(d + "/cross_section.png", std::ios::binary);
  char sig[8];
  png.read(sig, 8);
  EXPECT_EQ(std::string(sig + 1, 3), "PNG");
  // The report is JSON a reader parses, and its numbers are the result's, in its units.
  std::ifstream report(d + "/report.json");
  const nlohmann::json j = nlohmann::json::parse(report);
  EXPECT_EQ(j.at("converged").get<bool>(), r.converged);
  EXPECT_EQ(j.at("steps").get<std::string>(), r.steps.describe());
  EXPECT_EQ(j.at("mesh").at("tetrahedra").get<long>(), m.rest.T.rows());
  ASSERT_EQ(j.at("tumours").size(), r.tumours.size());
  for (size_t i = 0; i < r.tumours.size(); ++i) {
    const auto& t = j.at("tumours")[i];
    EXPECT_EQ(t.at("name").get<std::string>(), r.tumours[i].name);
    EXPECT_DOUBLE_EQ(t.at("centroid_distance_mm").get<double>(), r.tumours[i].centroid_distance * 1e3);
    for (int k = 0; k < 3; ++k) EXPECT_DOUBLE_EQ(t.at("centroid_supine_mm")[k].get<double>(), r.tumours[i].centroid[k] * 1e3);
  }
  ASSERT_EQ(j.at("step_reports").size(), r.reports.size());
  for (size_t i = 0; i < r.reports.size(); ++i) {
    EXPECT_EQ(j.at("step_reports")[i].at("step").get<std::string>(), r.reports[i].name);
    EXPECT_EQ(j.at("step_reports")[i].at("newton_iterations").get<int>(), r.reports[i].iterations);
    EXPECT_EQ(j.at("step_reports")[i].at("stop").get<std::string>(), r.reports[i].stop_reason);
  }
  const auto& rot = j.at("rigid_transform_supine_to_model").at("rotation");
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b) EXPECT_DOUBLE_EQ(rot[a][b].get<double>(), r.supine_to_model.linear()(a, b));
  EXPECT_EQ(j.at("warnings").get<std::vector<std::string>>(), r.warnings);
  const TetMesh back = read_tet_mesh(d + "/registered.vtk", LengthUnit::Millimetre);
  EXPECT_EQ(back.T.rows(), m.rest.T.rows());
}

TEST(Presets, UnknownPresetIsAnError) {
  expect_throw_with<InputError>([] { preset_options("ludicrous"); }, "unknown preset");
}

namespace {
// A soft phantom (E = 400 Pa) with stiff tumours (4 kPa) in the ground truth: large
// deformation (about 14 mm tumour motion), where landmark-only rigid fits are biased.
const std::string& soft_phantom_dir() {
  static const std::string dir = [] {
    const std::string d = (std::filesystem::temp_directory_path() / "btr_tests" / "phantom_soft").string();
    std::filesystem::remove_all(d);
    PhantomSceneOptions o;
    o.phantom.tet.cell_size = 0.009;
    o.phantom.surface_rings = 16;
    o.youngs_modulus = 400;
    o.tumour_youngs_modulus = 4000;
    write_phantom_scene(d, o);
    return d;
  }();
  return dir;
}
}  // namespace

TEST(RigidAlignment, RigidRegionsOverruleLandmarksOnDeformingSkin) {
  const Scene s = load_meshed_scene(soft_phantom_dir() + "/scene.yaml");
  Points prone_lm(s.landmark_anchors.size(), 3);
  for (size_t i = 0; i < s.landmark_anchors.size(); ++i) prone_lm.row(i) = s.landmark_anchors[i].position(s.prone.V).transpose();
  const Rigid landmark_fit = kabsch(s.landmark_supine, prone_lm);
  EXPECT_GT(landmark_fit.translation().norm(), 0.01) << "the landmarks' Kabsch fit absorbs the sag";
  const RegistrationResult r = register_scene(soft_phantom_dir() + "/scene.yaml");
  EXPECT_TRUE(r.icp_used);
  EXPECT_LT(r.supine_to_model.translation().norm(), 1e-4);  // truth: identity
  EXPECT_LT(rotation_angle(r.supine_to_model), 1e-3);
  for (const auto& t : r.tumours) {
    EXPECT_GT(t.rigid_centroid_distance, 0.01) << t.name;
    EXPECT_LT(t.centroid_distance, 0.2 * t.rigid_centroid_distance) << t.name;  // a biased rigid fit gives ~1x
  }
}

TEST(StiffTumour, KeepsTheTumourShapeCloserToTheTruth) {
  auto mean_axis_gap = [](const RegistrationResult& r) {
    double gap = 0;
    for (const auto& t : r.tumours) gap += std::abs(t.axis_ratio - t.truth_axis_ratio) / r.tumours.size();
    return gap;
  };
  // The phantom's scene gives the tumours' label region (10x); without it the model is homogeneous.
  const std::string homogeneous_scene = soft_phantom_dir() + "/homogeneous.yaml";
  btr::test::write_text(homogeneous_scene, without_key(phantom_scene_text(soft_phantom_dir()), "regions"));
  const RegistrationResult homogeneous = register_scene(homogeneous_scene);
  const RegistrationResult stiff = register_scene(soft_phantom_dir() + "/scene.yaml");
  EXPECT_LT(mean_axis_gap(stiff), 0.5 * mean_axis_gap(homogeneous));
  for (size_t i = 0; i < stiff.tumours.size(); ++i) {
    EXPECT_GT(stiff.tumours[i].axis_ratio, homogeneous.tumours[i].axis_ratio) << "homogeneous material flattens more";
    // Issue 13's target: within 5 % of the truth's axis ratio (the homogeneous model: about 30 % below).
    const auto& t = stiff.tumours[i];
    EXPECT_LT(std::abs(t.axis_ratio - t.truth_axis_ratio), 0.05 * t.truth_axis_ratio) << t.name;
  }
}

TEST(Registration, SupinePointCloudInsteadOfASurface) {
  // The supine scan as unorganized points (e.g. from a depth camera or a laser scanner).
  const Scene base = load_meshed_scene(phantom_dir() + "/scene.yaml");
  std::ofstream xyz(phantom_dir() + "/supine_points.xyz");
  xyz << "# x y z [mm]\n";
  for (Eigen::Index i = 0; i < base.supine_surface->V.rows(); ++i)
    xyz << base.supine_surface->V(i, 0) * 1e3 << ' ' << base.supine_surface->V(i, 1) * 1e3 << ' '
        << base.supine_surface->V(i, 2) * 1e3 << '\n';
  xyz.close();
  const std::string path = scene_with("supine:\n  cloud: supine_points.xyz\n  chest_ring: chest_ring.obj", "cloud_scene");
  const Scene s = load_meshed_scene(path);
  ASSERT_TRUE(s.supine_cloud);
  EXPECT_FALSE(s.supine_surface);
  EXPECT_EQ(s.supine_cloud->rows(), base.supine_surface->V.rows());
  const RegistrationResult r = register_scene(path);
  EXPECT_TRUE(r.steps.surface);
  EXPECT_LT(worst_error(r), 0.5e-3);
  expect_throw_with<InputError>([&] { read_point_cloud(phantom_dir() + "/nothing.pcd", LengthUnit::Millimetre); },
                                "unknown point cloud format");
}

TEST(SimulationMesh, ACoarserMeshKeepsChestWallLandmarksAndAccuracy) {
  const Scene scene = load_meshed_scene(phantom_dir() + "/scene.yaml");
  RegistrationOptions opt = preset_options("balanced");
  opt.simulation_cell_size = 0.012;  // the scene's own 12 mm: keep the scene's mesh
  EXPECT_FALSE(simulation_scene(scene, opt).has_value());
  opt.simulation_cell_size = 0.025;
  const std::optional<Scene> coarse = simulation_scene(scene, opt);
  ASSERT_TRUE(coarse.has_value());
  EXPECT_LT(coarse->prone.T.rows(), scene.prone.T.rows() / 2);
  EXPECT_EQ(coarse->landmark_anchors.size(), scene.landmark_anchors.size());
  // The chest wall is found again: every fixed vertex lies on the plane z = 0 of the prone model.
  ASSERT_GT(coarse->chest_wall.size(), 10u);
  for (int v : coarse->chest_wall) EXPECT_NEAR(coarse->prone.V(v, 2), 0.0, 1e-6);
  // The landmarks stay on the prone skin, within the coarse surface's approximation error
  // (facet distance 0.1 x cell size).
  for (size_t i = 0; i < scene.landmark_anchors.size(); ++i)
    EXPECT_LT((coarse->landmark_anchors[i].position(coarse->prone.V) - scene.landmark_anchors[i].position(scene.prone.V)).norm(),
              0.15 * opt.simulation_cell_size);
  std::vector<std::string> warnings;
  const RegistrationModel m = prepare_model(*coarse, warnings);
  const RegistrationResult r = run_registration(*coarse, m, opt);
  for (const auto& t : r.tumours) {
    EXPECT_LT(t.centroid_distance, 1.0e-3) << t.name;
    EXPECT_LT(t.centroid_distance, 0.5 * t.rigid_centroid_distance) << t.name;
  }
  expect_throw_with<InputError>([&] { with_simulation_mesh(scene, -1, 0); }, "must be positive");
}

namespace {
/// Two triangles forming the square [0, side]^2 in z = 0: open, its four sides are border.
SurfaceMesh square_in_z0(double side) {
  SurfaceMesh sq;
  sq.V.resize(4, 3);
  sq.V << 0, 0, 0, side, 0, 0, side, side, 0, 0, side, 0;
  sq.F.resize(2, 3);
  sq.F << 0, 1, 2, 0, 2, 3;
  return sq;
}
}  // namespace

TEST(SurfaceProjector, FlagsClosestPointsOnTheBorderOfAnOpenSurface) {
  const auto open = make_mesh_projector(square_in_z0(1.0));
  EXPECT_FALSE(open->project(Vec3(0.5, 0.4, 0.3)).on_boundary);  // above the inside
  EXPECT_FALSE(open->project(Vec3(0.5, 0.5, 0.1)).on_boundary);  // above the shared diagonal
  EXPECT_TRUE(open->project(Vec3(1.5, 0.5, 0.1)).on_boundary);   // beyond a side
  EXPECT_TRUE(open->project(Vec3(-0.2, -0.3, 0.0)).on_boundary); // beyond a corner
  // A closed surface has no border.
  const auto closed = make_mesh_projector(make_icosphere(Vec3::Zero(), 1.0, 2));
  for (const Vec3& p : {Vec3(2, 0, 0), Vec3(0.1, 0.2, 0.3), Vec3(-1, 1, 1)}) EXPECT_FALSE(closed->project(p).on_boundary);
}

TEST(SurfaceStep, LandmarksOnTheScanTakeTheirDepthFromItAndKeepWhatItDoesNotHold) {
  // A 10 cm square scan in z = 0 (metres). A landmark 2 mm above its inside is moved onto it,
  // with the normal there; one beyond max_projection_distance and one past its border (a skin
  // vertex would not be held there either) are kept as given, with a zero normal.
  const auto scan = make_mesh_projector(square_in_z0(0.1));
  SurfaceStepOptions o;
  Points t(3, 3);
  t << 0.03, 0.04, 0.002,   // above the inside
      0.05, 0.05, 0.05,     // 5 cm above: farther than max_projection_distance (3 cm)
      0.12, 0.05, 0.001;    // beyond a side: its closest point is on the border
  const LandmarksOnScan on = landmarks_on_scan(*scan, t, o);
  EXPECT_EQ(on.moved, 1);
  EXPECT_LT((on.targets.row(0) - Eigen::RowVector3d(0.03, 0.04, 0)).norm(), 1e-12);
  EXPECT_NEAR(std::abs(on.normals(0, 2)), 1.0, 1e-12);
  for (Eigen::Index i : {1, 2}) {
    EXPECT_EQ(on.targets.row(i), t.row(i)) << i;
    EXPECT_EQ(on.normals.row(i).norm(), 0.0) << i;
  }
  // Nearer than the distance cap the far landmark is moved too; with the border allowed, so is the last.
  o.max_projection_distance = 0.1;
  o.reject_boundary = false;
  EXPECT_EQ(landmarks_on_scan(*scan, t, o).moved, 3);
}

TEST(SurfaceProjector, InterpolatedNormalsAreContinuousAcrossEdgesAndCloserToTheSmoothSurface) {
  // A coarse sphere (162 vertices): its face normals jump by about 14 deg across an edge.
  const SurfaceMesh sphere = make_icosphere(Vec3::Zero(), 1.0, 2);
  const auto face = make_mesh_projector(sphere, MeshNormals::Face);
  const auto smooth = make_mesh_projector(sphere, MeshNormals::Interpolated);
  // Two points on the surface 1e-6 from the edge shared by face 0 and its neighbour, one on
  // each face (each its own closest point).
  const Eigen::Vector3i f0 = sphere.F.row(0).transpose();
  const Vec3 a = sphere.V.row(f0[0]), b = sphere.V.row(f0[1]), c = sphere.V.row(f0[2]);
  int opposite = -1;  // the neighbour's third vertex
  for (Eigen::Index f = 1; f < sphere.F.rows() && opposite < 0; ++f) {
    int shared = 0, other = -1;
    for (int k = 0; k < 3; ++k) {
      if (sphere.F(f, k) == f0[0] || sphere.F(f, k) == f0[1]) ++shared;
      else other = sphere.F(f, k);
    }
    if (shared == 2) opposite = other;
  }
  ASSERT_GE(opposite, 0);
  const Vec3 mid = 0.5 * (a + b);
  const Vec3 p_in = mid + 1e-6 * (c - mid).normalized();
  const Vec3 p_out = mid + 1e-6 * (Vec3(sphere.V.row(opposite).transpose()) - mid).normalized();
  const double jump_face = face->project(p_in).normal.cross(face->project(p_out).normal).norm();
  const double jump_smooth = smooth->project(p_in).normal.cross(smooth->project(p_out).normal).norm();
  EXPECT_GT(jump_face, 0.1);       // sin of the dihedral angle
  EXPECT_LT(jump_smooth, 1e-4);    // continuous
  // Over many directions the blended normal is nearer the sphere's (radial) than the face's,
  // points the same way as the face's, and the closest point is the same.
  double err_face = 0, err_smooth = 0;
  for (int i = 0; i < 200; ++i) {
    const Vec3 p = 1.3 * Vec3(std::sin(0.37 * i) * std::cos(1.1 * i), std::sin(0.37 * i) * std::sin(1.1 * i), std::cos(0.37 * i));
    const Projection pf = face->project(p), ps = smooth->project(p);
    EXPECT_NEAR((pf.point - ps.point).norm(), 0, 1e-12);
    EXPECT_GT(pf.normal.dot(ps.normal), 0.9);
    EXPECT_NEAR(ps.normal.norm(), 1, 1e-12);
    const Vec3 radial = ps.point.normalized();
    err_face += pf.normal.cross(radial).norm();
    err_smooth += ps.normal.cross(radial).norm();
  }
  EXPECT_LT(err_smooth, 0.5 * err_face);
}

TEST(Registration, APartialScanIsNotPulledOntoItsBorder) {
  // The supine surface as a depth camera would leave it: one side of the breast missing.
  // Skin hidden from the scan must not be held to the scan's edge.
  const Scene base = load_meshed_scene(phantom_dir() + "/scene.yaml");
  SurfaceMesh partial = *base.supine_surface;
  std::vector<Eigen::Vector3i> kept;
  for (Eigen::Index f = 0; f < partial.F.rows(); ++f) {
    Vec3 c = Vec3::Zero();
    for (int k = 0; k < 3; ++k) c += partial.V.row(partial.F(f, k)).transpose() / 3;
    if (c.y() < 0.03) kept.push_back(partial.F.row(f).transpose());
  }
  ASSERT_LT(kept.size(), static_cast<size_t>(partial.F.rows()));
  partial.F.resize(static_cast<Eigen::Index>(kept.size()), 3);
  for (size_t i = 0; i < kept.size(); ++i) partial.F.row(static_cast<Eigen::Index>(i)) = kept[i].transpose();
  Scene s = base;
  s.supine_surface = partial;
  std::vector<std::string> warnings;
  const RegistrationModel m = prepare_model(s, warnings);
  RegistrationOptions with = preset_options("balanced"), without = with;
  without.surface.reject_boundary = false;
  const RegistrationResult a = run_registration(s, m, with), b = run_registration(s, m, without);
  const StepReport& surface = a.reports.back();
  EXPECT_EQ(surface.name, "surface");
  EXPECT_LT(surface.constrained_skin, surface.skin_vertices);  // the hidden side is left free
  EXPECT_LT(worst_error(a), 1.0e-3);
  EXPECT_LT(worst_error(a), worst_error(b));
  std::printf("partial scan: worst tumour error %.3f mm with border rejection, %.3f mm without\n", worst_error(a) * 1e3,
              worst_error(b) * 1e3);
}

// Issue 11: a landmark pair given twice is merged with a warning, and more landmark vertices
// than subspace handles are capped with the reason (each row used to add a handle).
TEST(Landmarks, DuplicatesAreMergedAndHandlesCapped) {
  std::ifstream in(phantom_dir() + "/landmarks.csv");
  std::stringstream all;
  all << in.rdbuf();
  std::string rows, line;
  std::istringstream is(all.str());
  std::getline(is, line);  // header
  int n = 0;
  while (std::getline(is, line))
    if (!line.empty()) rows += line + "\n" + line + "\n", ++n;
  btr::test::write_text(phantom_dir() + "/landmarks_twice.csv", "prone_index,x,y,z\n" + rows);
  const Scene s = load_meshed_scene(scene_with("landmarks: landmarks_twice.csv", "landmarks_twice"));
  EXPECT_EQ(s.landmark_supine.rows(), n);
  ASSERT_FALSE(s.warnings.empty());
  EXPECT_NE(s.warnings[0].find(std::to_string(n) + " duplicate pairs merged"), std::string::npos) << s.warnings[0];
  std::vector<std::string> w;
  const RegistrationModel m = prepare_model(s, w);
  RegistrationOptions opt = preset_options("fast");
  opt.landmark.subspace.handles = 3;
  const RegistrationResult r = run_registration(s, m, opt);
  EXPECT_TRUE(test::has_warning(r, "more than the subspace's 3 handles"));
}

// Issue 10: without a rigid region the pose is solved with the deformation. On the phantom
// with its chest ring removed, a scan misaligned by 15 deg / 10 mm must give the aligned
// result, and the aligned scan must stay close to `steps: [landmarks, surface]` (which is
// told the pose). BENCHMARKS.md has the finer phantom across moduli.
TEST(RingFree, PoseSolvedWithTheDeformationIgnoresMisalignment) {
  const std::string text = btr::test::without_chest_ring(phantom_scene_text());
  const std::string dir = phantom_dir();
  btr::test::write_text(dir + "/ring_free.yaml", text);
  btr::test::write_text(dir + "/ring_free_told.yaml", text + "steps: [landmarks, surface]\n");
  btr::test::write_text(dir + "/ring_free_misaligned.yaml",
                        text + "misalignment: {rotation_deg: [0, 0, 15], translation_mm: [10, 0, 0]}\n");
  const RegistrationResult aligned = register_scene(dir + "/ring_free.yaml");
  const RegistrationResult told = register_scene(dir + "/ring_free_told.yaml");
  const RegistrationResult moved = register_scene(dir + "/ring_free_misaligned.yaml");
  EXPECT_TRUE(aligned.pose_solved_with_landmarks && aligned.pose_solved_with_surface && !aligned.icp_used);
  EXPECT_TRUE(aligned.converged && moved.converged);
  ASSERT_EQ(aligned.tumours.size(), moved.tumours.size());
  // Each in its own supine frame, truth moved with the scan. Issue 10 asks for 0.5 mm
  // (misaligned against aligned) and 0.05 mm (aligned against told the pose). With face
  // normals the skin ended at a jitter floor of about 0.03 mm per projection on this 12 mm mesh
  // and the paths stopped 0.11 mm apart; with interpolated normals the three agree to 0.001 mm
  // (0.145 mm each, measured).
  for (size_t i = 0; i < aligned.tumours.size(); ++i)
    EXPECT_LT(std::abs(aligned.tumours[i].centroid_distance - moved.tumours[i].centroid_distance), 0.05e-3);
  EXPECT_LT(worst_error(aligned), worst_error(told) + 0.05e-3) << worst_error(aligned) * 1e3 << " vs " << worst_error(told) * 1e3;
  std::printf("ring-free phantom: aligned %.3f mm, misaligned %.3f mm, told the pose %.3f mm\n", worst_error(aligned) * 1e3,
              worst_error(moved) * 1e3, worst_error(told) * 1e3);
}

// The 12 mm phantom made at 600 Pa without its chest ring, registered at the true E from the
// unloaded rest shape (`prone_gravity`, the element form of its truth): the model is right, so
// the pose-free limit is the truth. Writes unload_free / unload_told / unload_misaligned /
// prone_free.yaml (the last: the prone shape as rest) and returns the folder.
std::string ring_free_unloaded_dir() {
  static const std::string dir = [] {
    const std::string d = soft_phantom_dir("phantom12_soft_ringfree");
    std::string text = btr::test::without_chest_ring(without_key(without_key(phantom_scene_text(d), "material"), "steps"));
    text += "material: {youngs_modulus: 600, poisson_ratio: 0.49, density: 1000, volume_form: element}\nprone_gravity: [0, 0, 9.81]\n";
    btr::test::write_text(d + "/unload_free.yaml", text + "steps: auto\n");
    btr::test::write_text(d + "/unload_told.yaml", text + "steps: [unload, landmarks, surface]\n");
    btr::test::write_text(d + "/unload_misaligned.yaml",
                          text + "steps: auto\nmisalignment: {rotation_deg: [15, 0, 0], translation_mm: [0, 0, 10]}\n");
    btr::test::write_text(d + "/prone_free.yaml", without_key(text, "prone_gravity") + "steps: auto\n");
    return d;
  }();
  return dir;
}

// Options that run the surface step's alternation to its free limit (no hold: the tolerance is
// never first met, so nothing settles early).
RegistrationOptions to_the_free_limit(RegistrationOptions o) {
  o.surface.projection_tolerance = 1e-10;
  o.surface.max_projections = 2000;
  o.surface.stall_projections = 2000;
  return o;
}

// Issue 10's 0.05 mm bound at the soft end. With the prone shape as the rest shape a free pose
// absorbs part of the model's missing sag (bench/run_ringfree.sh: 6.9 against 0.58 mm at 400 Pa);
// with the rest shape unloaded the model is right, and the pose-free limit is where the same
// steps told the pose end, aligned or misaligned by 15 deg / 10 mm. The balanced preset stops
// short of that limit (a slow slide of the skin and the pose together, held where the check
// finds it: SurfaceStep.ASlowSlideTheStepsMissIsFoundAndHeld): 0.17 mm, where told it is 0.004.
TEST(RingFree, WithTheUnloadedRestShapeAFreePoseEndsWhereTheToldPoseDoes) {
  const std::string dir = ring_free_unloaded_dir();
  const RegistrationResult aligned = register_scene(dir + "/unload_free.yaml");
  const RegistrationResult moved = register_scene(dir + "/unload_misaligned.yaml");
  const RegistrationResult prone = register_scene(dir + "/prone_free.yaml");
  const RegistrationOptions tight = to_the_free_limit(preset_options("balanced"));
  const RegistrationResult limit = register_scene(dir + "/unload_free.yaml", tight);
  const RegistrationResult told = register_scene(dir + "/unload_told.yaml", tight);
  ASSERT_FALSE(aligned.reports.empty());
  EXPECT_EQ(aligned.reports.front().name, "unload");
  EXPECT_TRUE(aligned.pose_solved_with_surface && !aligned.icp_used && !told.pose_solved_with_surface);
  EXPECT_TRUE(aligned.converged && moved.converged && limit.converged && told.converged);
  ASSERT_EQ(aligned.tumours.size(), moved.tumours.size());
  for (size_t i = 0; i < aligned.tumours.size(); ++i)
    EXPECT_LT(std::abs(aligned.tumours[i].centroid_distance - moved.tumours[i].centroid_distance), 0.05e-3);
  EXPECT_LT(std::abs(worst_error(limit) - worst_error(told)), 0.05e-3) << worst_error(limit) * 1e3 << " vs " << worst_error(told) * 1e3;
  EXPECT_LT(rotation_angle(limit.supine_to_model), 0.05 * M_PI / 180);  // the truth's pose: identity
  EXPECT_LT(limit.supine_to_model.translation().norm(), 0.02e-3);
  // What the bound guards: the prone shape as rest, pose free, ends far from both.
  EXPECT_GT(worst_error(prone), worst_error(aligned) + 0.3e-3);
  std::printf("ring-free phantom at 600 Pa, unloaded, pose free: balanced %.3f mm (misaligned %.3f), its limit %.3f mm; "
              "told the pose %.3f mm; prone shape as rest %.3f mm\n",
              worst_error(aligned) * 1e3, worst_error(moved) * 1e3, worst_error(limit) * 1e3, worst_error(told) * 1e3,
              worst_error(prone) * 1e3);
}

// Issue 10, "converged means the criterion held": on that scene the balanced preset's steps
// read the free skin as 0.081 mm from its limit (contraction 0.72) while it was 0.16 mm RMS away,
// a slow slide of skin and pose under the faster modes. The check (one Newton step without the
// point springs) must read the distance and hold the sliding there.
TEST(SurfaceStep, ASlowSlideTheStepsMissIsFoundAndHeld) {
  const std::string path = ring_free_unloaded_dir() + "/unload_free.yaml";
  const Scene s = load_meshed_scene(path);
  std::vector<std::string> warnings;
  const RegistrationModel m = prepare_model(s, warnings);
  RegistrationOptions unchecked = preset_options("balanced");
  unchecked.surface.verify_free_limit = false;
  const RegistrationResult before = run_registration(s, m, unchecked);
  const RegistrationResult checked = run_registration(s, m, preset_options("balanced"));
  const RegistrationResult limit = run_registration(s, m, to_the_free_limit(preset_options("balanced")));
  auto skin_rms = [&](const Points& a, const Points& b) {
    double sum = 0;
    for (int v : m.skin) sum += (a.row(v) - b.row(v)).squaredNorm();
    return std::sqrt(sum / static_cast<double>(m.skin.size()));
  };
  const StepReport& b = before.reports.back();
  const StepReport& c = checked.reports.back();
  ASSERT_EQ(b.name, "surface (pose free)");
  const double missed = skin_rms(before.x, limit.x);
  // Without the check: "settled", with the distance under-read by half or more.
  EXPECT_TRUE(b.converged && b.sliding_held_from == 0 && b.free_limit_checked_at == 0);
  EXPECT_LT(b.fixed_point_distance, 0.6 * missed) << b.fixed_point_distance * 1e3 << " vs " << missed * 1e3 << " mm";
  EXPECT_GT(missed, unchecked.surface.projection_tolerance);
  // With it: the distance read within 30 %, the sliding held there, and the held alternation converged.
  EXPECT_TRUE(c.free_limit_missed);
  EXPECT_NEAR(c.free_limit_distance, skin_rms(before.x, limit.x), 0.3 * missed);
  EXPECT_EQ(c.sliding_held_from, c.free_limit_checked_at);
  EXPECT_TRUE(c.converged) << c.stop_reason;
  EXPECT_NE(c.stop_reason.find("free limit lay"), std::string::npos) << c.stop_reason;
  std::printf("read %.3f mm from the limit by the steps, %.3f mm by the check; %.3f mm RMS in fact\n", b.fixed_point_distance * 1e3,
              c.free_limit_distance * 1e3, missed * 1e3);
}

TEST(SurfaceStep, OptionsOutOfRangeAreNamed) {
  const Scene& s = test::coarse_phantom_scene();
  std::vector<std::string> warnings;
  const RegistrationModel m = prepare_model(s, warnings);
  const auto supine = make_mesh_projector(*s.supine_surface);
  Points x = m.rest.V;
  SurfaceStepOptions o;
  for (const double q : {1.5, -0.1, std::numeric_limits<double>::quiet_NaN()}) {
    o.hold_contraction = q;
    expect_throw_with<InputError>([&] { surface_step(m, *supine, o, x); }, "hold_contraction must be a number in [0, 1]");
  }
  o = SurfaceStepOptions{};
  for (const double a : {1.5, -0.1, std::numeric_limits<double>::quiet_NaN()}) {
    o.inversion_stall_alpha = a;
    expect_throw_with<InputError>([&] { surface_step(m, *supine, o, x); }, "inversion_stall_alpha must be a number in [0, 1]");
  }
  o = SurfaceStepOptions{};
  o.stall_projections = 0;
  expect_throw_with<InputError>([&] { surface_step(m, *supine, o, x); }, "stall_projections");
}

// The stiffness search's grid walk on misfits known in closed form (stiffness_grid_walk.h).
TEST(Stiffness, ABracketEndThatCannotBeSimulatedIsHalvedTowardsTheBest) {
  // A misfit |u - u*| in ln E that cannot be simulated below u_fail (too soft to unload).
  const double inf = std::numeric_limits<double>::infinity();
  auto misfit_with = [&](double u_star, double u_fail, std::vector<double>& calls) {
    return [=, &calls](double u) {
      calls.push_back(u);
      return u < u_fail ? inf : std::abs(u - u_star);
    };
  };
  using Bracket = std::array<std::pair<double, double>, 3>;
  std::vector<double> calls;
  // The halfway point fits worse than the best: it closes the bracket in one call.
  Bracket b{{{0.0, inf}, {4.0, 0.5}, {8.0, 3.5}}};
  EXPECT_TRUE(close_stiffness_bracket(b, 3, misfit_with(4.5, 1.0, calls)));
  EXPECT_EQ(calls, std::vector<double>({2.0}));
  EXPECT_EQ(b[0], std::make_pair(2.0, 2.5));
  EXPECT_EQ(b[1], std::make_pair(4.0, 0.5));
  // It fails too, then the next halfway point closes it.
  calls.clear();
  b = {{{0.0, inf}, {4.0, 0.5}, {8.0, 3.5}}};
  EXPECT_TRUE(close_stiffness_bracket(b, 3, misfit_with(4.5, 2.5, calls)));
  EXPECT_EQ(calls, std::vector<double>({2.0, 3.0}));
  EXPECT_EQ(b[0], std::make_pair(3.0, 1.5));
  // The minimum lies past the halfway point: it becomes the best, the old best the stiff end,
  // and the soft end is still closed.
  calls.clear();
  b = {{{0.0, inf}, {4.0, 1.5}, {8.0, 5.5}}};
  EXPECT_TRUE(close_stiffness_bracket(b, 3, misfit_with(2.5, 1.5, calls)));
  EXPECT_EQ(calls, std::vector<double>({2.0, 1.0, 1.5}));
  EXPECT_EQ(b[0], std::make_pair(1.5, 1.0));
  EXPECT_EQ(b[1], std::make_pair(2.0, 0.5));
  EXPECT_EQ(b[2], std::make_pair(4.0, 1.5));
  // The stiff end too; every end failing within the budget is reported, the grid point kept.
  calls.clear();
  b = {{{0.0, 4.5}, {4.0, 0.5}, {8.0, inf}}};
  EXPECT_TRUE(close_stiffness_bracket(b, 3, [&](double u) { calls.push_back(u); return u > 7.0 ? inf : std::abs(u - 4.5); }));
  EXPECT_EQ(b[2], std::make_pair(6.0, 1.5));
  calls.clear();
  b = {{{0.0, inf}, {4.0, 0.5}, {8.0, 3.5}}};
  EXPECT_FALSE(close_stiffness_bracket(b, 2, misfit_with(4.5, 3.9, calls)));
  EXPECT_EQ(calls, std::vector<double>({2.0, 3.0}));
  EXPECT_EQ(b[0].first, 3.0);
  EXPECT_FALSE(std::isfinite(b[0].second));
  calls.clear();
  b = {{{0.0, inf}, {4.0, 0.5}, {8.0, 3.5}}};
  EXPECT_FALSE(close_stiffness_bracket(b, 0, misfit_with(4.5, 1.0, calls)));
  EXPECT_TRUE(calls.empty());
}

TEST(Stiffness, TheGridWalkStopsPastTheMinimumAndSparesTheSoftEnd) {
  const double lo = 150, hi = 24000;
  const int n = 8;
  const std::vector<double> grid = stiffness_grid(lo, hi, n);
  ASSERT_EQ(grid.size(), 8u);
  EXPECT_NEAR(grid.front(), std::log(hi), 1e-12);
  EXPECT_NEAR(grid.back(), std::log(lo), 1e-12);
  auto on_grid = [&](double u) { return on_stiffness_grid(u, grid); };
  // Misfit growing linearly in |ln E - ln E*| (its square a parabola), minimum at 330 Pa: the
  // parabola through 1320, 640 and 310 Pa puts it before the grid's 150 Pa, so the point halfway
  // (215 Pa) is tried and, above the best, ends the walk; 150 Pa (the costly one) never is.
  int calls = 0;
  const StiffnessGridWalk soft = walk_stiffness_grid(lo, hi, n, [&](double u) {
    ++calls;
    return 1e-3 * std::abs(u - std::log(330.0));
  });
  ASSERT_EQ(soft.log_youngs_modulus.size(), soft.misfit.size());
  EXPECT_EQ(calls, static_cast<int>(soft.misfit.size()));
  for (double u : soft.log_youngs_modulus) EXPECT_GT(std::exp(u), 200) << "the soft end was simulated";
  EXPECT_NEAR(std::exp(soft.log_youngs_modulus.back()), std::sqrt(309.7 * 150.0), 1.0);
  EXPECT_FALSE(on_grid(soft.log_youngs_modulus.back()));
  EXPECT_NEAR(std::exp(soft.log_youngs_modulus[soft.best]), 309.7, 0.1);
  EXPECT_EQ(soft.best, static_cast<int>(soft.misfit.size()) - 2);  // bracketed: both neighbours simulated
  // The walk only falls, one candidate per grid point or halfway point.
  for (size_t i = 1; i < soft.log_youngs_modulus.size(); ++i)
    EXPECT_LT(soft.log_youngs_modulus[i], soft.log_youngs_modulus[i - 1]);

  // The same misfit with its minimum at 1000 Pa: the parabola puts it before 640 Pa, but that is
  // not the softest grid point, so the grid alone (stopping at 640 Pa, above 1.5x the best).
  const StiffnessGridWalk firm = walk_stiffness_grid(lo, hi, n, [](double u) { return 1e-3 * std::abs(u - std::log(1000.0)); });
  for (double u : firm.log_youngs_modulus) EXPECT_TRUE(on_grid(u)) << std::exp(u) << " Pa";
  EXPECT_NEAR(std::exp(firm.log_youngs_modulus.back()), 639.5, 0.1);

  // A misfit whose square is linear (no curvature to predict a minimum from): the grid alone,
  // stopped at its first point above 1.5x the best.
  const StiffnessGridWalk plain = walk_stiffness_grid(lo, hi, n, [](double u) { return 1e-3 * std::sqrt(std::abs(u - std::log(1000.0))); });
  for (double u : plain.log_youngs_modulus) EXPECT_TRUE(on_grid(u)) << std::exp(u) << " Pa";
  EXPECT_GT(plain.misfit.back(), 1.5 * plain.misfit[plain.best]);
  for (int i = plain.best + 1; i + 1 < static_cast<int>(plain.misfit.size()); ++i) EXPECT_LE(plain.misfit[i], 1.5 * plain.misfit[plain.best]);
  EXPECT_NEAR(std::exp(plain.log_youngs_modulus[plain.best]), 1320.4, 0.1);

  // A minimum beyond the soft end: every grid point, the last the best.
  const StiffnessGridWalk beyond = walk_stiffness_grid(lo, hi, n, [](double u) { return 1e-3 * std::abs(u - std::log(50.0)); });
  EXPECT_EQ(beyond.best, static_cast<int>(beyond.log_youngs_modulus.size()) - 1);
  EXPECT_NEAR(std::exp(beyond.log_youngs_modulus.back()), lo, 1e-9);

  expect_throw_with<InputError>([&] { walk_stiffness_grid(100, 120, n, [](double) { return 0.0; }); }, "0 < min < max / 1.5");
}
