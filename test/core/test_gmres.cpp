// GMRES (gmres.h), the solver of the rest shape's response in the linear region.
#include <random>

#include <Eigen/LU>
#include <gtest/gtest.h>

#include "breast_tumour_registration/fem/gmres.h"

using namespace btr;

// GMRES (gmres.h): a non-symmetric system solved to its tolerance; right preconditioning by
// the exact inverse takes one product; an unpreconditioned one takes at most its dimension.
TEST(Gmres, SolvesANonSymmetricSystemAndAnExactPreconditionerTakesOneProduct) {
  const int n = 40;
  std::mt19937 rng(3);
  std::normal_distribution<double> z;
  Eigen::MatrixXd A = 4.0 * Eigen::MatrixXd::Identity(n, n);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) A(i, j) += 0.3 * z(rng);
  Eigen::VectorXd b(n);
  for (int i = 0; i < n; ++i) b(i) = z(rng);
  const Eigen::VectorXd truth = A.partialPivLu().solve(b);
  ASSERT_GT((A - A.transpose()).norm(), 1.0);  // not symmetric: CG would not do
  auto apply_A = [&](const Eigen::VectorXd& v) { return Eigen::VectorXd(A * v); };
  auto identity = [](const Eigen::VectorXd& v) { return v; };
  Eigen::VectorXd x;
  const GmresResult plain = gmres(apply_A, identity, b, 1e-10, n + 5, x);
  EXPECT_TRUE(plain.converged);
  EXPECT_LE(plain.iterations, n);
  EXPECT_LT((A * x - b).norm(), 1.01e-10 * b.norm());  // the recursion's residual is the true one
  EXPECT_LT((x - truth).norm(), 1e-8 * truth.norm());
  const Eigen::PartialPivLU<Eigen::MatrixXd> lu(A);
  auto exact = [&](const Eigen::VectorXd& v) { return Eigen::VectorXd(lu.solve(v)); };
  const GmresResult pre = gmres(apply_A, exact, b, 1e-10, n, x);
  EXPECT_TRUE(pre.converged);
  EXPECT_EQ(pre.iterations, 1);
  EXPECT_LT((x - truth).norm(), 1e-10 * truth.norm());
  // Too few products: not converged, and the residual it reports is the one it left.
  const GmresResult short_run = gmres(apply_A, identity, b, 1e-10, 5, x);
  EXPECT_FALSE(short_run.converged);
  EXPECT_NEAR(short_run.relative_residual, (A * x - b).norm() / b.norm(), 1e-9);
}
