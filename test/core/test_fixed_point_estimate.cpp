#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "breast_tumour_registration/fem/fixed_point_estimate.h"

using btr::estimate_fixed_point;

TEST(FixedPointEstimate, AGeometricSequenceGivesItsRateAndRemainingPath) {
  std::vector<double> r;
  for (int k = 0; k < 6; ++k) r.push_back(std::pow(0.8, k));
  const auto e = estimate_fixed_point(r);
  EXPECT_NEAR(e.contraction, 0.8, 1e-12);
  EXPECT_FALSE(e.two_step);
  // The steps to come sum to r_5 (0.8 + 0.8^2 + ...) / ... = r_5 / (1 - 0.8) counted from x_5.
  EXPECT_NEAR(e.distance, std::pow(0.8, 5) / 0.2, 1e-12);
}

TEST(FixedPointEstimate, APeriodTwoOscillationIsMeasuredOverTwoSteps) {
  // Large and small steps alternating, each half contracting by 0.9 per two steps (as the
  // pose-free surface step on the ring-free phantom at 1000 Pa): one-step ratios exceed 1.
  std::vector<double> r;
  for (int k = 0; k < 10; ++k) r.push_back((k % 2 ? 1.0 : 3.0) * std::pow(0.9, k / 2));
  const auto e = estimate_fixed_point(r);
  EXPECT_TRUE(e.two_step);
  EXPECT_NEAR(e.contraction, std::sqrt(0.9), 1e-12);
  // The remaining path: the sum of all steps after the last, continued as the sequence does.
  double rest = 0;
  for (int k = 10; k < 2000; ++k) rest += (k % 2 ? 1.0 : 3.0) * std::pow(0.9, k / 2);
  const double expected = r.back() + rest;  // from the iterate before the last step
  EXPECT_GT(e.distance, 0.5 * expected);
  EXPECT_LT(e.distance, 2.0 * expected);
  EXPECT_TRUE(std::isfinite(e.distance));
}

TEST(FixedPointEstimate, GrowingOrTooFewStepsAreNotContracting) {
  EXPECT_TRUE(std::isinf(estimate_fixed_point({1.0, 0.5}).distance));
  EXPECT_TRUE(std::isnan(estimate_fixed_point({1.0, 0.5}).contraction));
  EXPECT_TRUE(std::isinf(estimate_fixed_point({1.0, 1.1, 1.2, 1.3}).distance));
  // A step of zero: at the limit.
  EXPECT_EQ(estimate_fixed_point({1.0, 0.5, 0.0}).distance, 0.0);
}
