// Numerical stability at the extremes: every case gives a finite state with non-increasing
// energy and either converges or stops with a stated reason; never NaN, never a hang.
#include <memory>

#include "breast_tumour_registration/fem/elastic_energy.h"
#include "breast_tumour_registration/fem/gravity_energy.h"
#include "breast_tumour_registration/fem/newton_solver.h"
#include "breast_tumour_registration/fem/spring_energy.h"
#include "breast_tumour_registration/fem/tet_kinematics.h"
#include "breast_tumour_registration/geometry/box_mesh.h"
#include "test_util.h"

using namespace btr;

namespace {

struct MiniBreast {
  TetMesh mesh = make_box_tet_mesh(4, 4, 3, Vec3(0.08, 0.08, 0.06));
  std::vector<bool> fixed;
  MiniBreast() {
    fixed.assign(mesh.V.rows(), false);
    for (Eigen::Index i = 0; i < mesh.V.rows(); ++i) fixed[i] = mesh.V(i, 2) == 0.0;  // chest wall
  }
};

void expect_sane(const NewtonResult& r, const Points& x) {
  EXPECT_TRUE(x.allFinite());
  EXPECT_TRUE(std::isfinite(r.energy));
  EXPECT_LE(r.energy, r.initial_energy + 1e-12 * std::abs(r.initial_energy));
  double last = r.initial_energy;
  for (const auto& it : r.history) {
    EXPECT_LE(it.energy, last + 1e-12 * std::abs(last)) << "energy increased at iteration " << it.iteration;
    last = it.energy;
  }
  EXPECT_LE(r.iterations, 100);
  if (!r.converged) {
    EXPECT_TRUE(r.reason == StopReason::MaxIterations || r.reason == StopReason::LineSearchFailed ||
                r.reason == StopReason::Stalled || r.reason == StopReason::InvertedAfterStall)
        << to_string(r.reason);
  }
}

struct MaterialCase {
  double E, nu, gz;
};
class MaterialExtremes : public ::testing::TestWithParam<MaterialCase> {};

}  // namespace

TEST_P(MaterialExtremes, GravitySolveStaysFiniteAndMonotone) {
  const MiniBreast s;
  const auto c = GetParam();
  TotalEnergy energy;
  energy.add(std::make_shared<ElasticEnergy>(s.mesh, std::vector<StableNeoHookean>{StableNeoHookean(c.E, c.nu)}));
  energy.add(std::make_shared<GravityEnergy>(s.mesh, 1000, Vec3(0, 0, c.gz)));
  NewtonSolver solver(std::make_shared<HessianAssembler>(static_cast<int>(s.mesh.V.rows()), s.mesh.T, s.fixed), s.mesh.T);
  Points x = s.mesh.V;
  NewtonOptions opt;
  opt.max_iterations = 100;
  const NewtonResult r = solver.solve(energy, x, opt);
  expect_sane(r, x);
  // A stall may let the line search invert, but a solve never ends with more inverted
  // elements than it started with (the uninverted stall state is kept instead).
  EXPECT_EQ(count_inverted(x, s.mesh.T), 0);
  EXPECT_EQ(r.inverted, 0);
  // Realistic tissue converges; the extremes may stop on the cap or stall, and say so. At
  // E = 200 Pa pressed onto its chest wall the mini breast stalls on a nearly flat element
  // (gradient 0.29 N of a 3.8 N weight), which used to be reported as converged; letting it
  // invert ends with 2 inverted elements, so the stall state is kept and reported.
  if (c.E >= 400) {
    EXPECT_TRUE(r.converged) << to_string(r.reason);
  }
  if (r.reason == StopReason::GradientTolerance) {
    EXPECT_LE(r.gradient_norm, opt.gradient_rel_tolerance * std::max(r.initial_gradient_norm, 0.0) + opt.gradient_abs_tolerance);
  }
}

INSTANTIATE_TEST_SUITE_P(
    Extremes, MaterialExtremes,
    ::testing::Values(MaterialCase{50, 0.49, -9.81}, MaterialCase{50, 0.49, 9.81}, MaterialCase{50, 0.0, -9.81},
                      MaterialCase{1e6, 0.49, -9.81}, MaterialCase{1e6, 0.499, 9.81}, MaterialCase{3400, 0.0, -9.81},
                      MaterialCase{3400, 0.499, -9.81}, MaterialCase{3400, 0.499, 9.81}, MaterialCase{200, 0.49, -9.81},
                      MaterialCase{12000, 0.45, 9.81}));

class PenaltyExtremes : public ::testing::TestWithParam<double> {};

TEST_P(PenaltyExtremes, LandmarkPullFromOneToHundredMillionNewtonPerMetre) {
  const MiniBreast s;
  const double w = GetParam();
  TotalEnergy energy;
  energy.add(std::make_shared<ElasticEnergy>(s.mesh, std::vector<StableNeoHookean>{StableNeoHookean(3400, 0.49)}));
  energy.add(std::make_shared<GravityEnergy>(s.mesh, 1000, Vec3(0, 0, -9.81)));
  auto pts = std::make_shared<SpringEnergy>();
  // Pull three top vertices 15 mm sideways and down.
  std::vector<int> top;
  for (Eigen::Index i = 0; i < s.mesh.V.rows(); ++i)
    if (s.mesh.V(i, 2) == 0.06 && s.mesh.V(i, 1) == 0.04) top.push_back(static_cast<int>(i));
  for (int v : top) pts->add_point(Anchor::vertex(v), s.mesh.V.row(v).transpose() + Vec3(0.015, 0, -0.01), w);
  energy.add(pts);
  NewtonSolver solver(std::make_shared<HessianAssembler>(static_cast<int>(s.mesh.V.rows()), s.mesh.T, s.fixed), s.mesh.T);
  Points x = s.mesh.V;
  const NewtonResult r = solver.solve(energy, x, NewtonOptions{});
  expect_sane(r, x);
  EXPECT_TRUE(r.converged) << to_string(r.reason);
  // Stronger springs get closer to the targets.
  const double residual = (x.row(top[0]).transpose() - pts->targets()[0]).norm();
  if (w >= 1e6) {
    EXPECT_LT(residual, 1e-3);
  }
  if (w <= 1) {
    EXPECT_GT(residual, 0.01);
  }
}

INSTANTIATE_TEST_SUITE_P(Weights, PenaltyExtremes, ::testing::Values(1.0, 1e2, 1e4, 1e6, 1e8));

TEST(Extremes, InvertedStartRecoversWithoutNewInversions) {
  const MiniBreast s;
  TotalEnergy energy;
  energy.add(std::make_shared<ElasticEnergy>(s.mesh, std::vector<StableNeoHookean>{StableNeoHookean(3400, 0.49)}));
  energy.add(std::make_shared<GravityEnergy>(s.mesh, 1000, Vec3(0, 0, -9.81)));
  NewtonSolver solver(std::make_shared<HessianAssembler>(static_cast<int>(s.mesh.V.rows()), s.mesh.T, s.fixed), s.mesh.T);
  // Push the top layer through the layer below: many inverted elements.
  Points x = s.mesh.V;
  for (Eigen::Index i = 0; i < x.rows(); ++i)
    if (s.mesh.V(i, 2) == 0.06) x(i, 2) = 0.025;
  const long inverted_start = count_inverted(x, s.mesh.T);
  ASSERT_GT(inverted_start, 0);
  long last = inverted_start;
  NewtonOptions opt;
  opt.callback = [&](const IterationInfo& it) {
    EXPECT_LE(it.inverted, last);
    last = it.inverted;
    return true;
  };
  const NewtonResult r = solver.solve(energy, x, opt);
  expect_sane(r, x);
  EXPECT_TRUE(r.converged) << to_string(r.reason);
  EXPECT_EQ(count_inverted(x, s.mesh.T), 0) << "stable Neo-Hookean should recover from inversion";
}
