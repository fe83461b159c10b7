#include <dlfcn.h>

#include <cstdlib>
#include <cstring>
#include <memory>
#include <vector>
#if defined(__GLIBC__)
#include <malloc.h>
#endif

#include "breast_tumour_registration/base/errors.h"
#include "breast_tumour_registration/fem/blas_threads.h"
#include "breast_tumour_registration/fem/heap_retention.h"
#include "breast_tumour_registration/fem/elastic_energy.h"
#include "breast_tumour_registration/fem/gravity_energy.h"
#include "breast_tumour_registration/fem/line_search.h"
#include "breast_tumour_registration/fem/spring_energy.h"
#include "breast_tumour_registration/fem/tet_kinematics.h"
#include "breast_tumour_registration/fem/newton_solver.h"
#include "breast_tumour_registration/geometry/box_mesh.h"
#include "breast_tumour_registration/geometry/validation.h"
#include "test_util.h"

using namespace btr;

namespace {

std::vector<bool> boundary_mask(const TetMesh& m) {
  std::vector<bool> b(m.V.rows(), false);
  const Triangles F = boundary_faces(m);
  for (Eigen::Index i = 0; i < F.size(); ++i) b[F.data()[i]] = true;
  return b;
}

}  // namespace

// Patch test: with the boundary moved by an affine map, a homogeneous hyperelastic body is
// in equilibrium exactly when every interior vertex follows the same map (F is constant).
TEST(NewtonSolver, PatchTestReproducesAnAffineDeformationExactly) {
  const TetMesh m = make_box_tet_mesh(4, 4, 4, Vec3(0.04, 0.04, 0.04));
  Mat3 A;
  A << 1.3, 0.2, -0.1, 0.05, 0.8, 0.3, -0.2, 0.1, 1.1;  // large, non-symmetric, det > 0
  const Vec3 b(0.01, -0.02, 0.005);
  const std::vector<bool> fixed = boundary_mask(m);
  Points x = m.V;
  Points expected = m.V;
  for (Eigen::Index i = 0; i < m.V.rows(); ++i) {
    expected.row(i) = (A * m.V.row(i).transpose() + b).transpose();
    if (fixed[i]) x.row(i) = expected.row(i);
  }
  TotalEnergy energy;
  energy.add(std::make_shared<ElasticEnergy>(m, std::vector<StableNeoHookean>{StableNeoHookean(5000, 0.45)}));
  NewtonSolver solver(std::make_shared<HessianAssembler>(static_cast<int>(m.V.rows()), m.T, fixed), m.T);
  NewtonOptions opt;
  opt.gradient_rel_tolerance = 1e-13;
  const NewtonResult r = solver.solve(energy, x, opt);
  EXPECT_TRUE(r.converged) << to_string(r.reason);
  EXPECT_LT((x - expected).cwiseAbs().maxCoeff(), 1e-12);
}

TEST(NewtonSolver, EnergyNeverIncreasesAndCallbackSeesEveryIteration) {
  const TetMesh m = make_box_tet_mesh(6, 2, 2, Vec3(0.12, 0.04, 0.04));
  std::vector<bool> fixed(m.V.rows(), false);
  for (Eigen::Index i = 0; i < m.V.rows(); ++i) fixed[i] = m.V(i, 0) == 0.0;
  TotalEnergy energy;
  energy.add(std::make_shared<ElasticEnergy>(m, std::vector<StableNeoHookean>{StableNeoHookean(2000, 0.45)}));
  auto gravity = std::make_shared<GravityEnergy>(m, 1000, Vec3(0, 0, -9.81));
  energy.add(gravity);
  NewtonSolver solver(std::make_shared<HessianAssembler>(static_cast<int>(m.V.rows()), m.T, fixed), m.T);
  Points x = m.V;
  int calls = 0;
  double last = std::numeric_limits<double>::infinity();
  NewtonOptions opt;
  opt.callback = [&](const IterationInfo& it) {
    ++calls;
    EXPECT_LE(it.energy, last);
    last = it.energy;
    EXPECT_GT(it.elapsed, 0.0);
    return true;
  };
  const NewtonResult r = solver.solve(energy, x, opt);
  EXPECT_TRUE(r.converged) << to_string(r.reason);
  EXPECT_EQ(calls, r.iterations);
  EXPECT_LT(r.energy, r.initial_energy);
  EXPECT_LE(r.gradient_norm, 1e-6 * r.initial_gradient_norm + 1e-10);
  // Fixed vertices did not move; the free end sagged.
  for (Eigen::Index i = 0; i < m.V.rows(); ++i)
    if (fixed[i]) {
      EXPECT_EQ((x.row(i) - m.V.row(i)).norm(), 0.0);
    }
  EXPECT_LT(x.col(2).minCoeff(), -0.01);

  // Warm start with the body's weight as force scale: the solution is accepted at once
  // (the symbolic factorization is reused when it does iterate).
  NewtonOptions warm;
  warm.force_scale = gravity->total_weight();
  const NewtonResult again = solver.solve(energy, x, warm);
  EXPECT_TRUE(again.converged);
  EXPECT_EQ(again.iterations, 0);
  // Without a force scale the tolerance is relative to the (tiny) starting residual.
  const NewtonResult tighter = solver.solve(energy, x, NewtonOptions{});
  EXPECT_TRUE(tighter.converged);
}

TEST(NewtonSolver, CallbackCanAbort) {
  const TetMesh m = make_box_tet_mesh(4, 2, 2, Vec3(0.08, 0.04, 0.04));
  std::vector<bool> fixed(m.V.rows(), false);
  for (Eigen::Index i = 0; i < m.V.rows(); ++i) fixed[i] = m.V(i, 0) == 0.0;
  TotalEnergy energy;
  energy.add(std::make_shared<ElasticEnergy>(m, std::vector<StableNeoHookean>{StableNeoHookean(300, 0.45)}));
  energy.add(std::make_shared<GravityEnergy>(m, 1000, Vec3(0, 0, -9.81)));
  NewtonSolver solver(std::make_shared<HessianAssembler>(static_cast<int>(m.V.rows()), m.T, fixed), m.T);
  Points x = m.V;
  NewtonOptions opt;
  opt.callback = [](const IterationInfo&) { return false; };
  const NewtonResult r = solver.solve(energy, x, opt);
  EXPECT_EQ(r.reason, StopReason::Aborted);
  EXPECT_EQ(r.iterations, 1);
  EXPECT_FALSE(r.converged);
}

TEST(NewtonSolver, NonFiniteStartIsAClearError) {
  const TetMesh m = make_box_tet_mesh(2, 2, 2, Vec3(0.04, 0.04, 0.04));
  TotalEnergy energy;
  energy.add(std::make_shared<ElasticEnergy>(m, std::vector<StableNeoHookean>{StableNeoHookean(3400, 0.49)}));
  NewtonSolver solver(std::make_shared<HessianAssembler>(static_cast<int>(m.V.rows()), m.T, std::vector<bool>{}), m.T);
  Points x = m.V;
  x(3, 1) = std::numeric_limits<double>::quiet_NaN();
  btr::test::expect_throw_with<SolverError>([&] { solver.solve(energy, x, NewtonOptions{}); }, "not finite");
}

// A stall is never convergence: a lagged direction is retried on a fresh factor, then a
// line search that refused inversions may invert, then it is a stall; an exact Newton step
// below the step tolerance is convergence.
TEST(NewtonSolver, StallsAreRetriedThenReportedAsStalls) {
  NewtonResult r;
  NewtonOptions o;
  ASSERT_TRUE(o.forbid_new_inversions);
  EXPECT_TRUE(recover_from_stall(StepOutcome::Stalled, true, o, r));
  EXPECT_TRUE(o.forbid_new_inversions);  // a fresh factor first
  EXPECT_TRUE(recover_from_stall(StepOutcome::NoDecrease, false, o, r));
  EXPECT_FALSE(o.forbid_new_inversions);
  EXPECT_TRUE(r.inversions_allowed);
  EXPECT_FALSE(recover_from_stall(StepOutcome::Stalled, false, o, r));
  EXPECT_FALSE(r.converged);
  EXPECT_EQ(r.reason, StopReason::Stalled);
  EXPECT_FALSE(recover_from_stall(StepOutcome::NoDecrease, false, o, r));
  EXPECT_FALSE(r.converged);
  EXPECT_EQ(r.reason, StopReason::LineSearchFailed);
  EXPECT_FALSE(recover_from_stall(StepOutcome::TooSmall, false, o, r));
  EXPECT_TRUE(r.converged);
  EXPECT_EQ(r.reason, StopReason::StepTolerance);
}

// The line search says when the no-new-inversion rule, not the energy, chose alpha: a spring
// pulls the apex of one tetrahedron through its base (the full step inverts it; alpha = 1/2
// leaves it exactly flat, also refused; 1/4 is taken). Without the rule alpha = 1 is taken.
TEST(LineSearch, SaysWhenTheInversionRuleCutTheStep) {
  Points x(4, 3);
  x << 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1;
  Tetrahedra T(1, 4);
  T << 0, 1, 2, 3;
  ASSERT_EQ(count_inverted(x, T), 0);
  TotalEnergy energy;
  auto spring = std::make_shared<SpringEnergy>();
  spring->add_point(Anchor::vertex(3), Vec3(0, 0, -1), 10.0);
  energy.add(spring);
  Points dx = Points::Zero(4, 3);
  dx(3, 2) = -2;  // the exact minimiser of the spring
  const double E0 = energy.value(x);
  const double slope = -2 * 10.0 * 2;  // g . dx with g_z = 10 * (1 - (-1)) = 20 at the apex
  Points out;
  LineSearchOptions o;
  const LineSearchResult ruled = backtracking_line_search(energy, x, dx, E0, slope, 0, T, o, out);
  ASSERT_TRUE(ruled.accepted);
  EXPECT_TRUE(ruled.inversion_limited);
  EXPECT_DOUBLE_EQ(ruled.alpha, 0.25);
  EXPECT_EQ(ruled.inverted, 0);
  o.forbid_new_inversions = false;
  const LineSearchResult free = backtracking_line_search(energy, x, dx, E0, slope, 0, T, o, out);
  ASSERT_TRUE(free.accepted);
  EXPECT_FALSE(free.inversion_limited);
  EXPECT_DOUBLE_EQ(free.alpha, 1.0);
  EXPECT_EQ(free.inverted, 1);
}

// CHOLMOD's dense blocks run on one OpenBLAS thread once a Newton solver exists: its threads
// only waited on each other on these problems (BENCHMARKS.md, "The stiffness search at the
// soft end"). An OPENBLAS_NUM_THREADS in the environment rules instead; another BLAS is left be.
TEST(NewtonSolver, RunsOpenBlasOnOneThreadUnlessTheEnvironmentSays) {
  const TetMesh m = make_box_tet_mesh(1, 1, 1, Vec3(0.1, 0.1, 0.1));
  NewtonSolver solver(std::make_shared<HessianAssembler>(static_cast<int>(m.V.rows()), m.T, std::vector<bool>{}), m.T);
  using GetThreads = int (*)();
  auto get = reinterpret_cast<GetThreads>(dlsym(RTLD_DEFAULT, "openblas_get_num_threads"));
  if (!get) GTEST_SKIP() << "the BLAS is not OpenBLAS";
  if (std::getenv("OPENBLAS_NUM_THREADS")) {
    EXPECT_FALSE(use_single_threaded_blas());
    EXPECT_EQ(get(), std::atoi(std::getenv("OPENBLAS_NUM_THREADS")));
  } else {
    EXPECT_TRUE(use_single_threaded_blas());
    EXPECT_EQ(get(), 1);
  }
}

// Freed memory stays in the process once a Newton solver exists: a 16 MB block is served from
// the heap, not mapped afresh, so repeated factorizations do not fault their workspace in again
// (BENCHMARKS.md, "The stiffness search and the heap"). A malloc setting in the environment rules
// instead.
TEST(NewtonSolver, KeepsFreedHeapMemoryUnlessTheEnvironmentSays) {
#if !defined(__GLIBC__)
  GTEST_SKIP() << "the allocator is not glibc's";
#else
  const TetMesh m = make_box_tet_mesh(1, 1, 1, Vec3(0.1, 0.1, 0.1));
  NewtonSolver solver(std::make_shared<HessianAssembler>(static_cast<int>(m.V.rows()), m.T, std::vector<bool>{}), m.T);
  const char* tunables = std::getenv("GLIBC_TUNABLES");
  if ((tunables && std::strstr(tunables, "glibc.malloc.")) || std::getenv("MALLOC_MMAP_THRESHOLD_") ||
      std::getenv("MALLOC_TRIM_THRESHOLD_")) {
    EXPECT_FALSE(keep_freed_heap_memory());
    return;
  }
  EXPECT_TRUE(keep_freed_heap_memory());
  const size_t mapped = mallinfo2().hblkhd;
  auto block = std::make_unique<std::vector<char>>(16u << 20, 1);
  EXPECT_EQ(mallinfo2().hblkhd, mapped) << "a 16 MB block was mapped on its own";
  block.reset();
  EXPECT_GE(mallinfo2().fordblks, 16u << 20) << "a freed 16 MB block left the heap";
#endif
}
