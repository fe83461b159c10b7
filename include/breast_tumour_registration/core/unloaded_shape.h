// The unloaded (stress-free) reference shape of a body imaged under gravity: the rest shape X
// whose equilibrium under that gravity, with the chest wall fixed, is the imaged shape x_p
// (thesis Sec. 5.2.3: the prone shape stands in for it; at the soft end that is the largest
// error of the method). Backward-displacement fixed point (Sellier 2011):
//
//   X_{k+1} = X_k + (x_p - phi(X_k)),   X_0 = phi_{-g}(x_p) (inverse gravity),
//
// phi(X) the forward equilibrium from rest X, accelerated by Anderson mixing (Walker and Ni
// 2011) over the last few iterates, falling back to the plain or a halved step when an
// extrapolated estimate inverts an element or its forward solve fails. Every forward solve is a Newton solve on one assembler,
// so CHOLMOD's symbolic analysis is done once; each starts from the last equilibrium's
// displacement applied to the new rest shape.
#pragma once

#include <string>
#include <vector>

#include "breast_tumour_registration/core/elastic_energy.h"
#include "breast_tumour_registration/core/newton_solver.h"

namespace btr {

struct UnloadOptions {
  double tolerance = 1e-5;   ///< [m] converged when re-simulating reproduces x_p within this at every vertex
  int max_iterations = 30;   ///< forward solves (a cap, reported as not converged)
  int anderson_depth = 5;    ///< 0: plain fixed point
  NewtonOptions newton;      ///< of each forward solve (its gradient tolerance should be far below `tolerance`)
};

struct UnloadResult {
  Points rest;          ///< the estimated stress-free positions (the fixed vertices keep x_p's)
  Points resimulated;   ///< phi(rest): the forward equilibrium from it
  bool converged = false;
  std::string stop_reason;
  int iterations = 0;          ///< fixed-point iterations (one forward solve each, after the inverse-gravity one)
  int newton_iterations = 0;   ///< over all forward solves
  /// newton_iterations over those of the first forward solve (the inverse-gravity solve from
  /// x_p: about what one plain gravity simulation of the model costs).
  double forward_solve_equivalents = 0;
  double max_mismatch = 0;     ///< [m] max |phi(rest) - x_p| over the vertices
  std::vector<double> mismatch_history;  ///< [m] per forward solve
  double seconds = 0;
};

struct UnloadProblem {
  const TetMesh* loaded = nullptr;  ///< the imaged (loaded) shape, e.g. the prone tet mesh [m]
  std::vector<int> fixed;           ///< fixed vertices (the chest wall)
  std::vector<StableNeoHookean> materials;
  std::vector<int> material_of;     ///< per tetrahedron (empty: all materials[0])
  VolumeForm volume_form = VolumeForm::Element;  ///< resolved (not Auto)
  double density = 1000;            ///< [kg/m^3]
  Vec3 gravity = Vec3(0, 0, 9.81);  ///< [m/s^2] the gravity the loaded shape was imaged under
};

/// Estimates the unloaded shape. Throws InputError for bad input and SolverError when a forward
/// solve fails outright; a cap or a diverging iteration ends with converged = false and the
/// reason, keeping the best estimate found.
UnloadResult estimate_unloaded_shape(const UnloadProblem& problem, const UnloadOptions& options = {});

}  // namespace btr
