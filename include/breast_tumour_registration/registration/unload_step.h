// The unload step: when the gravity the prone image was taken under is known, the model's rest
// shape becomes the estimated unloaded shape (unloaded_shape.h) instead of the prone shape, and
// every later step simulates from it with the supine gravity, starting from the prone positions.
// It depends on the model only (mesh, chest wall, materials), so it runs once per prepared model.
#pragma once

#include "breast_tumour_registration/fem/unloaded_shape.h"
#include "breast_tumour_registration/registration/registration_model.h"

namespace btr {

class StepSolvers;

/// Estimates the unloaded shape of `model` (from model.prone, under prone_gravity in the model
/// frame [m/s^2]) and makes it the rest shape; model.unload receives the report.
///
/// A converged estimate is used. One that stopped (a cap, divergence, a failed solve) is used
/// only when re-simulating from it reproduces the prone shape better than the prone shape as
/// rest would (its mismatch is below the prone sag the inverse-gravity solve measured);
/// otherwise the prone shape stays the rest shape. Either way the report says not converged,
/// and its note says which shape was kept. With quadratic elements
/// (MaterialParameters::unload_element_order) the linear shape is found first and refined
/// (refine_with_model_elements). `cache`: an engine's solvers, whose gravity solver (its
/// symbolic analysis) the linear forward solves reuse; null: they build their own.
StepReport unload_model(RegistrationModel& model, const Vec3& prone_gravity, const UnloadOptions& options = {},
                        StepSolvers* cache = nullptr);

/// The quadrature of the unload's quadratic elements (tet_quadrature): Keast's 4-point rule, the
/// one commercial 10-node tetrahedra use (it integrates the P2 stiffness of a straight element
/// exactly). Against the 14-point degree-5 rule on the 15 scenes of the balanced preset's choice
/// the worst tumour moved by at most 0.001 mm on 13, came nearer on 2 (by 0.088 and 0.007 mm),
/// and the unload step took a median 0.75 times as long, the call 0.87 (BENCHMARKS.md, "The
/// accurate preset on balanced's model, and the unload's 4-point rule"). Truth generators keep
/// the 14-point rule (ForwardGravityOptions' default).
constexpr int kUnloadQuadratureDegree = 2;

/// The unload problem of `model`'s mesh, chest wall and materials for the imaged shape `loaded`
/// (its vertices: model.prone, kept alive by the caller) under `gravity` [m/s^2].
/// with_model_elements: `options` with the model's elements for the forward solves
/// (MaterialParameters::unload_element_order) and, for quadratic ones, kUnloadQuadratureDegree.
UnloadOptions with_model_elements(UnloadOptions options, const RegistrationModel& model);
UnloadProblem unload_problem(const RegistrationModel& model, const TetMesh& loaded, const Vec3& gravity);

/// The forward solves the unload with the model's elements may take from the linear shape (a
/// budget, not a cap on a converging estimate), without load continuation: where it converged on
/// SfePy's two bodies (fat 500 to 3400 Pa) and the phantom's quadratic truth at 1000 Pa it did so
/// directly, in 3 to 7; on that phantom at 400 Pa it did not converge, and took 100 s over 11
/// continuation stages before this budget and this rule.
constexpr int kModelElementsForwardSolves = 12;

/// Where `model` unloads with quadratic elements (MaterialParameters::unload_element_order):
/// `unload` (an unloaded shape of `loaded` under `gravity` found with linear elements) is found
/// again with them, starting from it, within kModelElementsForwardSolves forward solves and
/// without load continuation. Their estimate replaces it where it converged or reproduces the
/// prone shape better; otherwise the linear shape stays and its stop reason says why. With linear
/// elements, nothing to do.
void refine_with_model_elements(const RegistrationModel& model, const TetMesh& loaded, const Vec3& gravity,
                                const UnloadOptions& options, UnloadResult& unload);

/// The step report of an unload (name "unload"; mismatch, cost, and how far the rest shape
/// moved from `prone`).
StepReport unload_report(const UnloadResult& unload, const Points& prone);

/// Makes `rest` (an unloaded shape found before, e.g. cached) the rest shape of `model`,
/// recording `report` as its unload step and `unloaded_under` as the gravity it was unloaded
/// under (zero: `rest` is not an unloaded shape, e.g. the prone shape itself), and `nodes` as its
/// quadratic model's equilibrium (RegistrationModel::unloaded_nodes; empty: none kept). Throws
/// InputError when the size does not match or an element of it is inverted.
void set_rest_shape(RegistrationModel& model, const Points& rest, const StepReport& report, const Vec3& unloaded_under,
                    const Points& nodes = Points());

}  // namespace btr
