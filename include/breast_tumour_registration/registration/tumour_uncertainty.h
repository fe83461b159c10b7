// Where the tumour may be: the linearised uncertainty of every registered tumour centroid
// (issue 14). At the surface step's equilibrium the gradient G(x, p) vanishes; for an uncertain
// input p the equilibrium moves by dx/dp = -H^-1 dG/dp (implicit differentiation). H is the
// Jacobian of the surface step's converged fixed point: the exact elastic Hessian with the chest
// wall fixed, plus per held skin vertex the springs that hold it there. With the skin's sliding
// held where it settled (SkinSliding::HeldWhereSettled, the default) those are w_point I +
// w_plane n n^T: the point spring keeps its anchor along the surface. With free sliding
// (SkinSliding::Free), (w_point + w_plane) n n^T: re-projecting onto the surface frees the
// tangential part of the point springs. The centroid's sensitivities come
// from three adjoint solves per tumour, lambda = H^-1 (dc/dx)^T, so that every input costs one
// dot product: dc/dp = -lambda^T dG/dp.
//
// Sources (uncertainty_sources.h; independent, Gaussian to first order): the Young's modulus of
// every tissue together (ln E about the nominal, with the sd of the log-uniform range, or, where
// the stiffness step estimated E, the sd the landmarks leave: StiffnessEstimate::log_sd),
// Poisson's ratio of every tissue together (linearised in the volume compliance
// q = (1 - 2 nu) / (2 nu), in which the response is nearer linear than in nu near 0.5: at a
// tightly converged registration re-registrations at nu 0.47 moved the tumours by 0.75 to 1.08
// of its prediction), with q's root mean square about the nominal over the uniform range (the
// range need not be centred on the nominal), the
// direction of gravity (a tilt about the two horizontal axes), and the supine surface's depth
// noise (along its normal, per held skin vertex), and the rigid pose when the fit that set it
// says how well it did (ICP on the rigid regions: IcpResult::pose_covariance; the supine data
// move rigidly in the model frame, the chest wall stays). Where the rest shape is an unloaded
// one (RegistrationModel::unloaded_under) it moves with E and nu too: dX/dp from the unload's
// own equation, G_prone(x_prone; X, p) = 0, by GMRES on differences of the gradient in X; its
// effect joins dG/dp. Where the surface step solved the pose with the deformation (no rigid
// region: FreePoseLinearisation) the pose stays free in the Jacobian and the landmarks that
// share it are a source, jointly with an estimated E that was fitted on them (where the step
// moved their targets onto the scan, SurfaceStepOptions::landmarks_on_scan, a landmark moves
// its target along the surface only, and the scan's depth noise there moves it along the
// normal; the stiffness fit takes the landmarks as given); the pipeline then
// linearises with the skin free to slide (SkinSliding::Free), however the step ended, as
// measured on two independent bodies (BENCHMARKS.md, "The linear region with the pose free").
// Not covered by the linearisation: the landmarks' localisation where ICP or the caller set the
// pose (except through an estimated E's sd), the landmark step's influence on where the surface step ends
// (it is a start, not an input, of the equilibrium), E's estimate compensating a wrong
// Poisson's ratio unless the landmark fit it came from is given (LandmarkStiffnessFit; the
// pipeline gives it), the element form's discretisation error, and model error beyond these
// inputs. Sampling (RegistrationEngine::sample_uncertainty) draws every source, the landmarks
// included, and takes the element form's discretisation error from a nodal reference
// (UncertaintySources::discretisation).
//
// Experimental, off by default: not yet validated (BENCHMARKS.md, issue 14). The machinery is
// exact: against re-solves of the energy it differentiates (held projections) it agrees within
// 2 % (test Uncertainty.HeldProjection*). What it leaves out: where the skin settled (the anchors)
// depends on the inputs too, through the landmark step and the approach to the scan; with free
// sliding the skin creeps along the scan and where the step stops sets its tangential position
// (on the 4 mm phantom the re-solved response to a gravity tilt was 2.5x the fixed point's). With
// the pose free and the landmarks a source the region held 93 to 96 % of noisy copies' tumours at
// its 95 % level on two independent bodies and the ring-free phantoms; with a rigid region
// setting the pose it is not calibrated. With E estimated, Poisson's ratio dominates the region, and at
// the balanced preset's stopping point (few projections, the skin's sliding still free) the
// tangent in q is 1.2 to 1.8 times the tightly converged one while the tumours' actual response
// is about the same, so the region is over-wide there (BENCHMARKS.md, "The linear region with
// Poisson's ratio"). Linearising on the held map instead fixes that for nu but overstates E's
// share 1.4 to 1.5 times on the coarse phantom, where the free map matches sampling.
#pragma once

#include <array>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "breast_tumour_registration/geometry/anchor.h"
#include "breast_tumour_registration/geometry/rigid_transform.h"
#include "breast_tumour_registration/geometry/surface_projector.h"
#include "breast_tumour_registration/io/uncertainty_sources.h"
#include "breast_tumour_registration/registration/registration_model.h"
#include "breast_tumour_registration/registration/surface_step.h"

namespace btr {

struct UncertaintyOptions {
  bool enabled = false;
  /// The inputs' distributions (uncertainty_sources.h; a scene's `uncertainty:` section). The
  /// linearisation takes ln E about the nominal modulus with the range's sd, Poisson's ratio
  /// (as its volume compliance), the gravity tilt and the depth noise; sampling draws every
  /// source.
  UncertaintySources sources;
  /// false: linearise the surface step's fixed point as its sliding option has it (held along
  /// the scan where it settled, or free to slide).
  /// true: linearise the surface step's last Newton problem with its projections held (point
  /// springs holding the skin tangentially too): an equilibrium of one fixed energy, which
  /// re-solves can reach to round-off, so that the machinery is checked exactly (tests).
  bool held_projections = false;
  /// > 0: the sd of ln E about the nominal modulus, in place of the range's. The pipeline sets
  /// it where the stiffness step estimated E from the landmarks (StiffnessEstimate::log_sd): the
  /// modulus is then known as well as the landmarks fix it, not only as well as the range says.
  double youngs_modulus_log_sd = 0;
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
  /// per unit of the volume compliance q = (1 - 2 nu) / (2 nu) [m] (volume_compliance)
  Vec3 d_volume_compliance = Vec3::Zero();
  Vec3 d_gravity_tilt[2] = {Vec3::Zero(), Vec3::Zero()};
  /// Per unit of a small rigid motion xi = (omega [rad], tau [m]) of the supine data in the model
  /// frame (supine -> model becomes exp(xi) of it; IcpResult::pose_covariance): the skin follows
  /// the moved data, the chest wall stays, and the result is mapped back by the moved pose.
  Eigen::Matrix<double, 3, 6> d_pose = Eigen::Matrix<double, 3, 6>::Zero();
  /// With a free pose (FreePoseLinearisation): per metre of each supine landmark moving, column
  /// 3 i + d for landmark i along axis d of the frame the supine surface was projected in
  /// (supine frame) [m/m]; the estimated E's response to it included when the landmark fit is
  /// given. Empty otherwise.
  Eigen::Matrix<double, 3, Eigen::Dynamic> d_landmarks;
};

struct UncertaintyResult {
  std::vector<TumourUncertainty> tumours;  ///< as model.tumours
  std::string note;                        ///< what the linearisation assumed or could not do
  double seconds = 0;
  /// The unloaded rest shape's response to E and nu was included (the model was unloaded), in
  /// this many GMRES products with the prone gradient's rest-shape derivative and this time [s].
  bool rest_shape_follows = false;
  int rest_response_iterations = 0;
  double rest_response_seconds = 0;
  /// With a LandmarkStiffnessFit: d ln E / d q, how the estimate follows the volume compliance
  /// (0: not followed, E taken independent of nu).
  bool estimate_follows_poisson_ratio = false;
  double log_youngs_modulus_per_compliance = 0;
  /// With the landmarks a source (a free pose) and the landmark fit an estimated E came from:
  /// the estimate moves with the landmarks (jointly with their direct effect), and E's own
  /// source keeps only the part of its sd the landmarks' noise does not explain.
  bool estimate_follows_landmarks = false;
  /// Then: the sd of ln E the landmarks' noise gives the estimate (their sd over |dr/d ln E|, as
  /// linearised here), and the sd E keeps as an independent source (the rest of the estimate's).
  double log_sd_from_landmarks = 0, log_sd_independent = 0;
};

/// The volume compliance q = mu / lambda_L = (1 - 2 nu) / (2 nu) of Poisson's ratio nu: the
/// variable the linearisation takes Poisson's ratio in (0 at incompressibility).
double volume_compliance(double nu);
/// Its inverse: Poisson's ratio nu = 1 / (2 (1 + q)) of the volume compliance q.
double poisson_ratio_of_compliance(double q);

/// The model's materials with every tissue's Poisson's ratio set to `nu` and its Young's modulus
/// scaled by `youngs_factor` (as set_poisson_ratio and scale_stiffness do to a whole model).
std::vector<StableNeoHookean> materials_at(const RegistrationModel& m, double nu, double youngs_factor = 1.0);

/// sqrt(E[(q(nu) - q(nominal_nu))^2]) for nu uniform over `range` (0 when the range is {0, 0}:
/// held): the spread of the true compliance about the method's.
double volume_compliance_rms(const std::array<double, 2>& range, double nominal_nu);

/// Where the stiffness step estimated E from the landmarks: the landmarks and the supine
/// gravity-only prediction they were fitted on (StiffnessEstimate::supine_prediction). With it
/// the linearisation lets the estimate follow Poisson's ratio: a true nu other than the method's
/// moves the predicted landmarks, and the estimate moves E to fit them again,
/// d ln E / d q = -(dr/d ln E . dr/dq) / |dr/d ln E|^2 with r the landmarks' residual after
/// their best rigid fit; the tumour's response to q is then dc/dq + dc/d ln E d ln E / d q.
struct LandmarkStiffnessFit {
  std::vector<Anchor> anchors;
  Points supine_prediction;  ///< model frame [m]
};

/// d ln E / d q of the landmark fit at `model` (its E the estimate; its rest shape unloaded, as
/// model.unloaded_under says, or the prone one): what the linearisation takes. InputError for
/// fewer than 3 landmarks or a prediction that does not match the mesh.
double log_youngs_modulus_per_compliance(const RegistrationModel& model, const LandmarkStiffnessFit& fit);

/// A skin vertex held on the supine surface: its target point and unit normal (model frame).
struct HeldSkinVertex {
  int vertex = 0;
  Vec3 point = Vec3::Zero();
  Vec3 normal = Vec3::UnitZ();
};

/// Where the surface step solved the pose jointly with the deformation (no rigid region
/// decides it; RigidFreeSurfaceEnergy): the pose it ended on and the landmarks that share it
/// (SurfaceStepOptions::pose_points_weight). The linearisation then keeps the pose free, as
/// that energy does (eliminated, its Hessian's rank-6 part applied by the Woodbury identity),
/// maps the centroids out through the pose as it moves, and takes the supine landmarks'
/// localisation (UncertaintySources::landmark_sd) as a source: each target moving isotropically.
/// On ring-free bodies those springs hold the skin's sliding and the pose where the landmarks
/// put them, and their noise was most of the error (BENCHMARKS.md, issue 14).
struct FreePoseLinearisation {
  Rigid model_to_projector = Rigid::Identity();  ///< the pose the surface step ended on
  std::vector<Anchor> landmarks;
  Points landmark_targets;   ///< in the projector's frame, one row per landmark (0 rows: none)
  double landmark_weight = 0;  ///< [N/m] per landmark
  /// Per landmark (or 0 rows: none): a unit normal where the surface step moved the target onto
  /// the scan (LandmarksOnScan::normals), so that only the landmark's motion along the surface
  /// moves it; a zero row: the target moves with its landmark.
  Points landmark_normals;
};

/// The linearisation at x with these held skin vertices (the core of the function below, which
/// projects the skin first).
UncertaintyResult linearised_tumour_uncertainty(const RegistrationModel& model, const Points& x,
                                                const std::vector<HeldSkinVertex>& held, const Rigid& model_to_supine,
                                                const SurfaceStepOptions& surface, const UncertaintyOptions& opt,
                                                const std::optional<Mat6>& pose_covariance = std::nullopt,
                                                const LandmarkStiffnessFit* stiffness_fit = nullptr,
                                                const FreePoseLinearisation* free_pose = nullptr);

/// x: the surface step's equilibrium (model frame); supine: the projector it ended on, which
/// sees the model through model_to_projector; model_to_supine maps the result into the supine
/// frame. pose_covariance: that of the rigid pose (supine -> model) as IcpResult::
/// pose_covariance gives it, a source "rigid_pose"; none: the pose is held. free_pose: the pose
/// was solved with the deformation (then no pose_covariance; model_to_projector is its pose), a
/// source "landmarks" where landmarks share it. Throws SolverError when the fixed-point Jacobian
/// cannot be factorized, InputError for a free pose with a covariance.
UncertaintyResult linearised_tumour_uncertainty(const RegistrationModel& model, const Points& x,
                                                const SurfaceProjector& supine, const Rigid& model_to_projector,
                                                const Rigid& model_to_supine, const SurfaceStepOptions& surface,
                                                const UncertaintyOptions& opt,
                                                const std::optional<Mat6>& pose_covariance = std::nullopt,
                                                const LandmarkStiffnessFit* stiffness_fit = nullptr,
                                                const FreePoseLinearisation* free_pose = nullptr);

/// The spread of the registered tumour centroids over whole re-registrations with sampled
/// inputs (RegistrationEngine::sample_uncertainty): the reference the linearisation is judged by,
/// and what the pipeline itself does, stopping criteria included.
struct SampledUncertainty {
  struct Tumour {
    Mat3 covariance = Mat3::Zero();  ///< of the sampled centroids about their mean, supine frame [m^2]
    /// [m] the 95th percentile of the distance to the nominal centroid over the samples, each
    /// moved by the discretisation error (sampled_distances)
    double radius_95 = 0;
    double radius_95_sources = 0;    ///< [m] the same over the samples alone (the listed sources)
    /// The element form's discretisation error as estimated (UncertaintySources::discretisation):
    /// the nodal reference's centroid minus the nominal one, supine frame [m]; zero where it was
    /// not estimated. The region's samples are moved by it (mean_shift is theirs before).
    Vec3 discretisation = Vec3::Zero();
    Vec3 mean_shift = Vec3::Zero();  ///< sample mean minus the nominal centroid [m]
    std::vector<Vec3> centroids;     ///< every finished sample's centroid, supine frame [m]
    /// Per vertex of the registered tumour surface: the 95th percentile of its distance to the
    /// nominal position over the samples, each moved by that vertex's discretisation shift [m]
    /// (the margin shell grows the surface by it).
    std::vector<double> vertex_radius_95;
  };
  std::vector<Tumour> tumours;
  int samples = 0;        ///< registrations that finished
  int not_converged = 0;  ///< of them, not converged (kept: what the pipeline would have given)
  int failed = 0;         ///< that threw (left out)
  double seconds_per_sample = 0;
  bool discretisation_estimated = false;  ///< the nodal reference converged and its shift is in the region
  double discretisation_seconds = 0;      ///< the nodal reference registration [s] (0: not run)
  std::string note;       ///< what was not sampled, and why
};

/// The 95th percentile of the distances, by the nearest rank (0 for none).
double percentile_95(std::vector<double> distances);

/// The distances from the nominal point of sampled offsets (sample minus nominal) with the
/// element form's estimated discretisation error: each offset moved by `shift`, the nodal
/// reference's displacement from the nominal (|o + shift|). The shift is taken as the bias it
/// was measured to be, not as a spread: on truth our elements did not make it pointed along the
/// element form's error (cosine 0.56 to 1.00); taken as Gaussian along itself instead, the
/// region held 84 % at its 68 % level on the phantom's quadratic truth (BENCHMARKS.md, "The
/// element form's own error in the tumour's region"). A zero shift gives the norms.
std::vector<double> sampled_distances(const std::vector<Vec3>& offsets, const Vec3& shift);

/// The two horizontal axes the gravity-direction source tilts about (both the linearisation and
/// the sampling): a unit vector orthogonal to `gravity`, then gravity's direction crossed with it.
std::array<Vec3, 2> gravity_tilt_axes(const Vec3& gravity);

/// P(|X| <= r) for X ~ N(0, covariance): the level of the smallest sphere about the mean that
/// holds a point at distance r (deterministic quadrature, 1e-4 absolute).
double probability_within(const Mat3& covariance, double r);

/// The radius of the sphere about the mean holding 95 % of N(0, covariance) (deterministic
/// quadrature over the eigenvalues: exact to 1e-4 relative).
double radius_95(const Mat3& covariance);

}  // namespace btr
