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

#include "breast_tumour_registration/fem/elastic_energy.h"
#include "breast_tumour_registration/fem/forward_gravity.h"

namespace btr {

struct UnloadOptions {
  double tolerance = 1e-5;   ///< [m] converged when re-simulating reproduces x_p within this at every vertex
  int max_iterations = 30;   ///< forward solves per fixed point (a cap, reported as not converged)
  /// When the direct fixed point does not converge: load continuation of the inverse problem,
  /// the unloaded shape for growing fractions of the gravity (the first fraction, grown 1.5x
  /// after a converged stage, halved after a failed one), intermediate stages converged to
  /// stage_tolerance; at most max_stages stages (0: no continuation).
  double first_stage_fraction = 0.25;
  double stage_tolerance = 1e-4;  ///< [m]
  int max_stages = 12;
  int anderson_depth = 5;    ///< 0: plain fixed point
  /// A budget on the forward solves of the whole estimate, over the direct attempt and every
  /// continuation stage (0: none). Spent, the estimate stops as not converged, saying so, with
  /// the best estimate found; a caller that only compares candidates (the stiffness search)
  /// stops a hopeless one with it instead of letting continuation run on.
  int max_forward_solves = 0;
  /// Each forward solve (its Newton gradient tolerance should be far below `tolerance`) and
  /// its load continuation when one load step does not converge.
  ForwardGravityOptions forward;
};

struct UnloadResult {
  Points rest;          ///< the estimated stress-free positions (the fixed vertices keep x_p's)
  ElementOrder elements = ElementOrder::Linear;  ///< of the forward model it inverts (options.forward.element_order)
  Points resimulated;   ///< phi(rest): the forward equilibrium from it
  /// Quadratic elements: every node of that equilibrium (corners, then edge nodes), where the
  /// quadratic unload's equation is linearised (quadratic_unload_equation.h); else empty.
  Points resimulated_nodes;
  bool converged = false;
  std::string stop_reason;
  int iterations = 0;          ///< forward gravity solves attempted, over all stages (inverse-gravity ones included)
  int continuation_stages = 0; ///< 0: solved directly; else the direct attempt + the continuation stages
  int newton_iterations = 0;   ///< over all forward solves
  int load_steps = 0;          ///< load-continuation fractions solved (0: every forward solve took the whole load at once)
  /// newton_iterations over those of the first converged forward solve (the inverse-gravity
  /// solve from x_p: about what one plain gravity simulation of the model costs).
  double forward_solve_equivalents = 0;
  double max_mismatch = 0;     ///< [m] max |phi(rest) - x_p| over the vertices (infinite: no forward solve from an estimate converged, rest = x_p)
  /// [m] max |X_0 - x_p|, X_0 the inverse-gravity estimate: about the sag, i.e. how far the
  /// loaded shape as its own rest shape would miss it (0 when that solve failed)
  double inverse_gravity_lift = 0;
  std::vector<double> mismatch_history;  ///< [m] per fixed-point iteration of the final (full-gravity) stage
  double seconds = 0;
};

struct UnloadProblem {
  const TetMesh* loaded = nullptr;  ///< the imaged (loaded) shape, e.g. the prone tet mesh [m]
  std::vector<int> fixed;           ///< fixed vertices (the chest wall)
  std::vector<StableNeoHookean> materials;
  std::vector<int> material_of;     ///< per tetrahedron (empty: all materials[0])
  VolumeForm volume_form = VolumeForm::Element;  ///< resolved (not Auto)
  double nodal_element_share = 0;   ///< MaterialParameters::nodal_element_share
  double density = 1000;            ///< [kg/m^3]
  Vec3 gravity = Vec3(0, 0, 9.81);  ///< [m/s^2] the gravity the loaded shape was imaged under
  /// A first estimate of the rest shape (e.g. the unloaded shape of a nearby stiffness): the
  /// direct attempt starts from it instead of the inverse-gravity solve. Null: inverse gravity.
  const Points* initial_rest = nullptr;
  /// A Newton solver bound to this problem's pattern to reuse (ForwardGravity's `shared`).
  NewtonSolver* solver = nullptr;
};

/// Estimates the unloaded shape. Throws InputError for bad input and SolverError when a forward
/// solve fails outright; a cap or a diverging iteration ends with converged = false and the
/// reason, keeping the best estimate found.
UnloadResult estimate_unloaded_shape(const UnloadProblem& problem, const UnloadOptions& options = {});

}  // namespace btr
