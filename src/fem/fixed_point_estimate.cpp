#include "breast_tumour_registration/fem/fixed_point_estimate.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace btr {

FixedPointEstimate estimate_fixed_point(const std::vector<double>& r) {
  const double inf = std::numeric_limits<double>::infinity();
  FixedPointEstimate e{std::numeric_limits<double>::quiet_NaN(), inf, false};
  const size_t n = r.size();
  if (n < 3) return e;
  const size_t k = n - 1;
  const auto ratio = [inf](double a, double b) { return b > 0 ? a / b : (a > 0 ? inf : 0.0); };
  const double q1 = std::max(ratio(r[k], r[k - 1]), ratio(r[k - 1], r[k - 2]));
  e.contraction = q1;
  if (q1 < 1) {
    e.distance = r[k] / (1 - q1);
    return e;
  }
  if (n < 4) return e;
  const double q2 = std::max(ratio(r[k], r[k - 2]), ratio(r[k - 1], r[k - 3]));
  if (!(q2 < 1)) return e;
  e.two_step = true;
  e.contraction = std::sqrt(q2);
  e.distance = (r[k] + q2 * r[k - 1]) / (1 - q2);
  return e;
}

}  // namespace btr
