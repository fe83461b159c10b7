// How far a fixed-point iteration x <- G(x) still is from its limit, from the norms of its
// steps r_j = |G(x_j) - x_j| alone. For a contraction with rate q the remaining path is at most
// the sum of the steps to come, r_k / (1 - q). The rate is measured, cautiously:
//  - one step: q = the larger of the last two ratios r_k / r_{k-1}, r_{k-1} / r_{k-2};
//  - two steps, where a one-step ratio exceeds 1 because the steps alternate large and small
//    (a period-2 oscillation, as the surface step shows when its pose is free): q2 = the larger
//    of r_k / r_{k-2}, r_{k-1} / r_{k-3}, and the remaining path (r_k + q2 r_{k-1}) / (1 - q2),
//    which for a monotone sequence is r_k / (1 - q) again.
#pragma once

#include <vector>

namespace btr {

struct FixedPointEstimate {
  double contraction;  ///< per step (for the two-step estimate the square root of q2); NaN: too few steps
  double distance;     ///< estimated distance to the limit, in the steps' unit; infinite: not contracting
  bool two_step;       ///< the two-step estimate was used
};

/// From the step norms in order (>= 0). Fewer than 3 steps: contraction NaN, distance infinite.
FixedPointEstimate estimate_fixed_point(const std::vector<double>& steps);

}  // namespace btr
