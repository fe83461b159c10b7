// The stiffness search's first phase (stiffness_step.h): which candidate moduli to simulate
// before the refinement. A log-spaced grid from the stiff end, stopped once past a clear minimum
// of the landmark misfit: a candidate above 1.5x the best's. That brackets the minimum; the next
// softer candidate would be the costliest of the search (on SfePy's fat-1000 body with the nodal
// volume term: 3.1 of 8.3 s) and changes the estimate only where the misfit rises and then falls
// again.
//
// Softer candidates cost more, steeply at the soft end, where the unload needs load
// continuation: on SfePy's fat-300 body with the nodal volume term the 150 Pa candidate took two
// minutes, the 310 Pa one 1.5 s. So before the grid's softest point, where the last three
// candidates, still falling, put a convex parabola's minimum (in log E, on the squared misfit)
// before it, the point halfway to it is tried first. Above the best, it brackets the minimum on
// its own (the rise the parabola predicted; no 1.5x margin needed); below, it is the best and the
// grid goes on. Only there: elsewhere the full step is cheap, and the halfway point's narrower
// bracket moved where the refinement's 5 % tolerance stopped (a labelled 3400 Pa phantom
// estimated at 3747 instead of 3578 Pa).
#pragma once

#include <array>
#include <functional>
#include <utility>
#include <vector>

namespace btr {

struct StiffnessGridWalk {
  std::vector<double> log_youngs_modulus;  ///< ln E [Pa] of every candidate, in the order simulated (falling)
  std::vector<double> misfit;              ///< [m] as misfit_at returned it (infinite: the candidate failed)
  int best = -1;                           ///< index of the least misfit (the first, if none is finite)
};

/// The grid: ln E [Pa] of `grid_points` log-spaced moduli from max_youngs_modulus down to
/// min_youngs_modulus, the order the walk takes them in. InputError as walk_stiffness_grid.
std::vector<double> stiffness_grid(double min_youngs_modulus, double max_youngs_modulus, int grid_points);

/// Walks `grid_points` log-spaced moduli from max_youngs_modulus down to min_youngs_modulus,
/// calling misfit_at(ln E) for each candidate it simulates. InputError for a range that is not
/// 0 < min < max / 1.5 or fewer than 3 grid points.
StiffnessGridWalk walk_stiffness_grid(double min_youngs_modulus, double max_youngs_modulus, int grid_points,
                                      const std::function<double(double)>& misfit_at);

/// Before the refinement: a bracket (ln E, misfit), ln E ascending, about its best point [1],
/// whose end could not be simulated (a misfit that is not finite: a neighbour too soft to unload,
/// a forward solve that failed). Each such end moves halfway towards the best point, calling
/// misfit_at there, up to max_halvings times per side: a point that still fails becomes the
/// end, one that fits worse than the best closes the bracket, and one that fits better becomes
/// the best (the old best the other end) with the failed end still to close. Before this the
/// search kept the grid point unrefined (not converged): 4 of 64 sampled re-registrations on
/// SfePy's bodies. Returns whether both ends are finite.
bool close_stiffness_bracket(std::array<std::pair<double, double>, 3>& bracket, int max_halvings,
                             const std::function<double(double)>& misfit_at);

}  // namespace btr
