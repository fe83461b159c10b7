// Backtracking (Armijo) line search shared by the full-space and subspace Newton solvers:
// never accepts an energy increase, a non-finite energy, or (optionally) a state with more
// inverted tetrahedra than the current one.
#pragma once

#include "breast_tumour_registration/fem/inversion_check.h"
#include "breast_tumour_registration/fem/total_energy.h"

namespace btr {

struct LineSearchOptions {
  int max_steps = 40;
  double armijo = 1e-4;
  bool forbid_new_inversions = true;
};

struct LineSearchResult {
  bool accepted = false;
  double alpha = 0;
  double energy = 0;
  long inverted = 0;
  /// A longer step met the Armijo condition but inverted tetrahedra the current state has not:
  /// the inversion rule, not the energy, set alpha.
  bool inversion_limited = false;
};

/// Tries x + alpha dx for alpha = 1, 1/2, ...; on acceptance x_out holds the new state.
/// E0, slope (= g . dx, negative for descent) and inverted0 describe the current state x;
/// `inversions` counts the inverted elements (an empty check: none).
LineSearchResult backtracking_line_search(const TotalEnergy& energy, const Points& x, const Points& dx, double E0,
                                          double slope, long inverted0, const InversionCheck& inversions,
                                          const LineSearchOptions& opt, Points& x_out);

}  // namespace btr
