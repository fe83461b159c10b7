#include "breast_tumour_registration/registration/stiffness_grid_walk.h"

#include <cmath>

#include "breast_tumour_registration/base/errors.h"

namespace btr {

std::vector<double> stiffness_grid(double min_youngs_modulus, double max_youngs_modulus, int grid_points) {
  if (!(min_youngs_modulus > 0) || !(max_youngs_modulus > 1.5 * min_youngs_modulus) || grid_points < 3)
    throw InputError("stiffness: the range must satisfy 0 < min < max / 1.5 [Pa], with >= 3 grid points");
  const double lo = std::log(min_youngs_modulus), hi = std::log(max_youngs_modulus);
  std::vector<double> u(static_cast<size_t>(grid_points));
  for (int i = 0; i < grid_points; ++i) u[static_cast<size_t>(i)] = lo + (hi - lo) * (grid_points - 1 - i) / (grid_points - 1);
  return u;
}

StiffnessGridWalk walk_stiffness_grid(double min_youngs_modulus, double max_youngs_modulus, int grid_points,
                                      const std::function<double(double)>& misfit_at) {
  const std::vector<double> grid = stiffness_grid(min_youngs_modulus, max_youngs_modulus, grid_points);
  StiffnessGridWalk w;
  auto& u_of = w.log_youngs_modulus;
  auto& f_of = w.misfit;
  auto add = [&](double u) {
    u_of.push_back(u);
    f_of.push_back(misfit_at(u));
    return static_cast<int>(u_of.size()) - 1;
  };
  int& best = w.best;
  for (size_t g = 0; g < grid.size(); ++g) {
    const double u = grid[g];
    const int m = static_cast<int>(u_of.size());
    if (g + 1 == grid.size() && m >= 3 && best == m - 1 && std::isfinite(f_of[m - 3])) {  // the next is the softest, the costliest
      const double u0 = u_of[m - 3], u1 = u_of[m - 2], u2 = u_of[m - 1];
      const double f0 = f_of[m - 3] * f_of[m - 3], f1 = f_of[m - 2] * f_of[m - 2], f2 = f_of[m - 1] * f_of[m - 1];
      // Divided differences of the squared misfit in u (u falling from u0 to u2).
      const double d01 = (f1 - f0) / (u1 - u0), d12 = (f2 - f1) / (u2 - u1), curvature = 2 * (d12 - d01) / (u2 - u0);
      if (curvature > 0 && 0.5 * (u1 + u2) - d12 / curvature > u) {  // the parabola's minimum lies before u
        const int h = add(0.5 * (u2 + u));
        if (f_of[h] > f_of[best]) break;
        best = h;
      }
    }
    const int j = add(u);
    if (best < 0 || f_of[j] < f_of[best]) best = j;
    else if (std::isfinite(f_of[best]) && f_of[j] > 1.5 * f_of[best]) break;
  }
  return w;
}

bool close_stiffness_bracket(std::array<std::pair<double, double>, 3>& bracket, int max_halvings,
                             const std::function<double(double)>& misfit_at) {
  for (const size_t side : {size_t(0), size_t(2)})
    for (int h = 0; h < max_halvings && !std::isfinite(bracket[side].second); ++h) {
      const double u = 0.5 * (bracket[side].first + bracket[1].first);
      const double m = misfit_at(u);
      if (!std::isfinite(m)) {
        bracket[side].first = u;
      } else if (m < bracket[1].second) {
        bracket[2 - side] = bracket[1];
        bracket[1] = {u, m};
      } else {
        bracket[side] = {u, m};
      }
    }
  return std::isfinite(bracket[0].second) && std::isfinite(bracket[2].second);
}

}  // namespace btr
