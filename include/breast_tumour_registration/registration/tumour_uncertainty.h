// Where the tumour may be: the linearised uncertainty of every registered tumour centroid
// (issue 14). At the surface step's equilibrium the gradient G(x, p) vanishes; for an uncertain
// input p the equilibrium moves by dx/dp = -H^-1 dG/dp (implicit differentiation). H is the
// Jacobian of the converged projection fixed point: the exact elastic Hessian with the chest
// wall fixed, plus (w_point + w_plane) n n^T per held skin vertex (re-projecting onto the
// surface frees the tangential part of the point springs). The centroid's sensitivities come
// from three adjoint solves per tumour, lambda = H^-1 (dc/dx)^T, so that every input costs one
// dot product: dc/dp = -lambda^T dG/dp.
//
// Sources (independent, Gaussian to first order): the Young's modulus of every tissue together
// (ln E), the direction of gravity (a tilt about the two horizontal axes), and the supine
// surface's depth noise (along its normal, per held skin vertex). Not covered: the landmark
// step's influence on where the surface step ends (it is a start, not an input, of the
// equilibrium), the rigid pose (held at its solution), Poisson's ratio, and model error beyond
// these inputs.
//
// Experimental, off by default: not yet validated. Against re-solves of the whole registration
// the sensitivity to E agrees along gravity for most tumours but not across it, where the
// surface step's stopping point (the skin slides slowly along the scan), not the equilibrium,
// sets the answer; the coverage is not calibrated (BENCHMARKS.md, issue 14).
#pragma once

#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "breast_tumour_registration/geometry/rigid_transform.h"
#include "breast_tumour_registration/geometry/surface_projector.h"
#include "breast_tumour_registration/registration/registration_model.h"
#include "breast_tumour_registration/registration/surface_step.h"

namespace btr {

struct UncertaintyOptions {
  bool enabled = false;
  /// sd of ln E (every tissue scaled together). Default: a log-uniform E over 200 to 3000 Pa,
  /// ln(15) / sqrt(12) = 0.78, i.e. breast tissue whose stiffness nobody measured.
  double youngs_modulus_log_sd = 0.78;
  /// sd of the tilt of the supine gravity about each horizontal axis [deg] (a table not level,
  /// a patient not flat).
  double gravity_direction_deg = 2.0;
  /// sd of the supine surface along its normal, independent per held skin vertex [m].
  double depth_noise = 0.001;
};
/// Throws InputError naming the field for a negative or non-finite value.
void validate_uncertainty_options(const UncertaintyOptions& o);

struct TumourUncertainty {
  Mat3 covariance = Mat3::Zero();  ///< of the centroid, supine frame [m^2]
  double radius_95 = 0;            ///< [m] a sphere about the registered centroid holding the true one with 95 %
  /// Per source: its name and its share of the covariance (supine frame [m^2]).
  std::vector<std::pair<std::string, Mat3>> sources;
  /// Sensitivities of the centroid (supine frame): per unit ln E [m], per radian of gravity tilt
  /// about the model frame's two horizontal axes [m/rad].
  Vec3 d_log_youngs_modulus = Vec3::Zero();
  Vec3 d_gravity_tilt[2] = {Vec3::Zero(), Vec3::Zero()};
};

struct UncertaintyResult {
  std::vector<TumourUncertainty> tumours;  ///< as model.tumours
  std::string note;                        ///< what the linearisation assumed or could not do
  double seconds = 0;
};

/// x: the surface step's equilibrium (model frame); supine: the projector it ended on, which
/// sees the model through model_to_projector; model_to_supine maps the result into the supine
/// frame. Throws SolverError when the fixed-point Jacobian cannot be factorized.
UncertaintyResult linearised_tumour_uncertainty(const RegistrationModel& model, const Points& x,
                                                const SurfaceProjector& supine, const Rigid& model_to_projector,
                                                const Rigid& model_to_supine, const SurfaceStepOptions& surface,
                                                const UncertaintyOptions& opt);

/// The radius of the sphere about the mean holding 95 % of N(0, covariance) (deterministic
/// quadrature over the eigenvalues: exact to 1e-4 relative).
double radius_95(const Mat3& covariance);

}  // namespace btr
