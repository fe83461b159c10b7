#include "breast_tumour_registration/fem/line_search.h"

#include <algorithm>
#include <cmath>


namespace btr {

LineSearchResult backtracking_line_search(const TotalEnergy& energy, const Points& x, const Points& dx, double E0,
                                          double slope, long inverted0, const InversionCheck& inversions,
                                          const LineSearchOptions& opt, Points& x_out) {
  LineSearchResult r;
  double alpha = 1.0;
  for (int ls = 0; ls < opt.max_steps; ++ls, alpha *= 0.5) {
    x_out = x + alpha * dx;
    const double E = energy.value(x_out);
    if (!std::isfinite(E) || E > E0 + opt.armijo * alpha * std::min(slope, 0.0)) continue;
    const long inv = inversions.count(x_out);
    if (opt.forbid_new_inversions && inv > inverted0) {
      r.inversion_limited = true;
      continue;
    }
    r.accepted = true;
    r.alpha = alpha;
    r.energy = E;
    r.inverted = inv;
    return r;
  }
  return r;
}

}  // namespace btr
