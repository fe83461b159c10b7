#include <cmath>

#include <Eigen/LU>
#include <gtest/gtest.h>

#include "breast_tumour_registration/base/errors.h"
#include "breast_tumour_registration/fem/anderson_acceleration.h"

using namespace btr;

namespace {

// Iterations until |x - x*| < tol for x <- G(x), plain or accelerated.
template <class Map>
int iterations_to(const Map& G, Eigen::VectorXd x, const Eigen::VectorXd& fixed, double tol, int depth, int cap = 2000) {
  AndersonAcceleration aa(depth > 0 ? depth : 1);
  for (int k = 1; k <= cap; ++k) {
    const Eigen::VectorXd g = G(x);
    x = depth > 0 ? aa.next(x, g) : g;
    if ((x - fixed).norm() < tol) return k;
  }
  return cap + 1;
}

}  // namespace

TEST(Anderson, SolvesALinearContractionInAboutItsDimensionWherePlainIterationCrawls) {
  // G(x) = A x + b with a spectral radius of 0.95: plain iteration needs ~ log(tol)/log(0.95).
  const int n = 6;
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(n, n);
  for (int i = 0; i < n; ++i) A(i, i) = 0.95 - 0.1 * i;
  A(0, 1) = 0.2;
  A(2, 4) = -0.3;
  const Eigen::VectorXd b = Eigen::VectorXd::LinSpaced(n, 1.0, 2.0);
  const Eigen::VectorXd fixed = (Eigen::MatrixXd::Identity(n, n) - A).lu().solve(b);
  auto G = [&](const Eigen::VectorXd& x) { return Eigen::VectorXd(A * x + b); };
  const int plain = iterations_to(G, Eigen::VectorXd::Zero(n), fixed, 1e-8, 0);
  const int accelerated = iterations_to(G, Eigen::VectorXd::Zero(n), fixed, 1e-8, n);
  EXPECT_GT(plain, 300);
  EXPECT_LE(accelerated, n + 3);  // GMRES-like: exact after n + 1 differences, up to round-off
}

TEST(Anderson, SpeedsUpANonlinearContractionWithAShortHistory) {
  // x_i <- 0.9 x_i + 0.1 cos(x_{i+1}): a contraction with a nonlinear coupling.
  const int n = 20;
  auto G = [&](const Eigen::VectorXd& x) {
    Eigen::VectorXd g(n);
    for (int i = 0; i < n; ++i) g(i) = 0.9 * x(i) + 0.1 * std::cos(x((i + 1) % n));
    return g;
  };
  Eigen::VectorXd fixed = Eigen::VectorXd::Zero(n);
  for (int k = 0; k < 5000; ++k) fixed = G(fixed);
  ASSERT_LT((G(fixed) - fixed).norm(), 1e-13);
  const int plain = iterations_to(G, Eigen::VectorXd::Constant(n, 2.0), fixed, 1e-9, 0);
  const int accelerated = iterations_to(G, Eigen::VectorXd::Constant(n, 2.0), fixed, 1e-9, 5);
  EXPECT_GT(plain, 100);  // about log(1e-9)/log(0.9 + coupling)
  EXPECT_LT(accelerated, plain / 5) << "plain " << plain << ", accelerated " << accelerated;
}

TEST(Anderson, FirstProposalIsThePlainIterateAndResetForgets) {
  AndersonAcceleration aa(3);
  const Eigen::VectorXd x = Eigen::VectorXd::Constant(4, 1.0), g = Eigen::VectorXd::Constant(4, 0.5);
  EXPECT_TRUE(aa.next(x, g).isApprox(g));
  EXPECT_EQ(aa.columns(), 0);
  aa.next(g, Eigen::VectorXd::Constant(4, 0.3));
  EXPECT_EQ(aa.columns(), 1);
  aa.reset();
  EXPECT_EQ(aa.columns(), 0);
  EXPECT_TRUE(aa.next(x, g).isApprox(g));
  EXPECT_THROW(AndersonAcceleration(0), InputError);
  EXPECT_THROW(aa.next(x, Eigen::VectorXd::Zero(3)), InputError);
}
