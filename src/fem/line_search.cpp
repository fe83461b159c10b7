#include "breast_tumour_registration/fem/line_search.h"

#include <algorithm>
#include <cmath>

#include "breast_tumour_registration/fem/tet_kinematics.h"

namespace btr {

LineSearchResult backtracking_line_search(const TotalEnergy& energy, const Points& x, const Points& dx, double E0,
                                          double slope, long inverted0, const Tetrahedra& T,
                                          const LineSearchOptions& opt, Points& x_out) {
  LineSearchResult r;
  double alpha = 1.0;
  for (int ls = 0; ls < opt.max_steps; ++ls, alpha *= 0.5) {
    x_out = x + alpha * dx;
    const double E = energy.value(x_out);
    if (!std::isfinite(E) || E > E0 + opt.armijo * alpha * std::min(slope, 0.0)) continue;
    const long inv = T.rows() ? count_inverted(x_out, T) : 0;
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
