// The stiffness step: the tissue's Young's modulus estimated from the data, for scenes that
// say `material: {youngs_modulus: estimate}`. The unloaded shape depends on the stiffness as
// much as on the geometry (a breast of 200 Pa sags ten times as far as one of 2 kPa): with an
// assumed E far from the patient's, the unloaded shape is wrong by about the difference of
// the sags and no later step can undo it.
//
// For a candidate E (every material scaled by the same factor, so a heterogeneous model keeps
// its ratios) the model is unloaded from the prone shape under the prone gravity, then loaded
// under the supine gravity; the objective is the RMS misfit of the landmarks so predicted to
// the supine landmarks after their best rigid fit (Kabsch), so it does not depend on the pose.
// The search is a log-spaced grid from the stiff end, stopped once the misfit has clearly
// passed its minimum (the soft candidates are the costly ones; stiffness_grid_walk.h), then
// parabolic refinement in log E around the best point (a neighbour too soft to simulate is
// first halved towards it: close_stiffness_bracket). Equilibrium is invariant under scaling E and gravity together,
// so a candidate is simulated with the gravities divided by the factor.
#pragma once

#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "breast_tumour_registration/fem/energy_term.h"
#include "breast_tumour_registration/fem/unloaded_shape.h"
#include "breast_tumour_registration/geometry/anchor.h"
#include "breast_tumour_registration/registration/registration_model.h"

namespace btr {

class StepSolvers;

struct StiffnessOptions {
  double min_youngs_modulus = 150;    ///< [Pa] of the model's first material
  double max_youngs_modulus = 24000;  ///< [Pa]
  int grid_points = 8;                ///< log-spaced over the range
  double relative_tolerance = 0.05;   ///< refinement stops when a step changes E by less than this
  int max_refinements = 6;
  /// A neighbour of the best grid point that cannot be simulated (too soft to unload, a forward
  /// solve that fails) is replaced by the point halfway to the best one, up to this many times
  /// per side, before the grid point is kept unrefined (not converged).
  int max_end_halvings = 3;
  /// [m] A candidate's unload stops once re-simulating reproduces the prone shape within this
  /// (or unload.tolerance, if larger); only the chosen candidate is then finished to
  /// unload.tolerance. The misfit moves by about this much, far less than between candidates.
  double candidate_tolerance = 1e-4;
  /// A candidate's unload may take at most max(min_candidate_forward_solves,
  /// candidate_budget_factor x the most forward solves a simulated candidate took so far);
  /// past it the candidate counts as one that cannot be simulated (as above). Candidates that
  /// converge took 2 to 13 on the bodies measured; one that continuation could not carry took
  /// 194 (a minute) before failing anyway. 0: no budget.
  double candidate_budget_factor = 4;
  int min_candidate_forward_solves = 30;
  UnloadOptions unload;               ///< of every candidate's unload, and of the chosen one's finish
};

/// One candidate of the search.
struct StiffnessCandidate {
  double youngs_modulus = 0;  ///< [Pa] of the model's first material
  double misfit = std::numeric_limits<double>::infinity();  ///< [m] RMS landmark misfit (inf: not simulated)
  int forward_solves = 0;     ///< its unload's forward solves, and its supine solve
  double seconds = 0;
  std::string failure;        ///< why it could not be simulated (empty: it was)
};

struct StiffnessEstimate {
  double scale = 1;           ///< E / the model's E (every material)
  double youngs_modulus = 0;  ///< [Pa] the estimate for the model's first material
  double misfit = 0;          ///< [m] RMS landmark misfit of the gravity-only prediction at the estimate (its candidate's unload, within candidate_tolerance of the finished one)
  bool converged = false;     ///< the refinement met relative_tolerance inside the range
  bool at_bound = false;      ///< the best candidate is an end of the range (the estimate is a bound)
  std::string stop_reason;
  std::vector<StiffnessCandidate> evaluations;  ///< in the order evaluated
  int landmarks = 0;
  /// [m] |dr / d ln E| at the estimate, r the Kabsch-fitted landmark residual (3n): from the
  /// simulated candidates nearest the estimate on each side (0: none was).
  double landmark_sensitivity = 0;
  /// The sd of ln E about the estimate that landmark noise of `landmark_sd` [m] per axis gives
  /// (Gauss-Newton, linear about the estimate), widened where the misfit left per residual
  /// degree of freedom is larger than that noise (model error). 0 when not known: at a bound of
  /// the range, or no neighbour was simulated.
  double log_sd(double landmark_sd) const;
  Points rest;                ///< the unloaded shape at the estimate
  /// The supine gravity-only equilibrium at the estimate (its candidate's, model frame [m]):
  /// the prediction whose landmarks were fitted. The linear region differentiates it to see how
  /// the estimate follows a Poisson's ratio other than the method's (tumour_uncertainty.h).
  Points supine_prediction;
  UnloadResult unload;        ///< its unload
  double seconds = 0;
};

/// Estimates the stiffness of `model` (its prone shape model.prone; its materials as the
/// reference) from the supine landmark positions `supine` (any frame, one row per anchor).
/// Throws InputError for fewer than 3 landmarks or a bad range; a range in which no candidate
/// could be simulated is a SolverError. `cache`: an engine's solvers; every candidate's forward
/// solves then share its gravity solver (one symbolic analysis for the whole search and across
/// calls); null: each candidate builds its own.
StiffnessEstimate estimate_stiffness(const RegistrationModel& model, const Vec3& prone_gravity,
                                     const std::vector<Anchor>& anchors, const Points& supine,
                                     const StiffnessOptions& options = {}, StepSolvers* cache = nullptr);

/// The model with every material scaled by `scale` (material.youngs_modulus too).
void scale_stiffness(RegistrationModel& model, double scale);
/// The model with every material's Poisson's ratio set to `nu`, each keeping its Young's
/// modulus (material.poisson_ratio too); InputError outside [0, 0.5). The volume form stays as
/// prepared.
void set_poisson_ratio(RegistrationModel& model, double nu);

}  // namespace btr
