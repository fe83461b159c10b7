// The scene-driven registration pipeline: it runs only the steps the scene's inputs call for
// (rigid alignment, optional gravity pre-step, landmark-guided, surface-guided) and reports
// the tumours in the supine frame with the figures of merit.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "breast_tumour_registration/io/scene.h"
#include "breast_tumour_registration/registration/icp_alignment.h"
#include "breast_tumour_registration/registration/landmark_step.h"
#include "breast_tumour_registration/registration/rigid_regions.h"
#include "breast_tumour_registration/registration/stiffness_step.h"
#include "breast_tumour_registration/registration/surface_step.h"
#include "breast_tumour_registration/registration/tumour_uncertainty.h"
#include "breast_tumour_registration/registration/unload_step.h"

namespace btr {

struct RegistrationOptions {
  std::string preset = "balanced";
  IcpOptions icp;
  RigidRegionOptions rigid_regions;  ///< symmetry checks of the rigid regions (its icp field is replaced by `icp`)
  LandmarkStepOptions landmark;
  SurfaceStepOptions surface;
  NewtonOptions gravity;  ///< gravity pre-step
  StiffnessOptions stiffness;  ///< stiffness step (its range is the scene's)
  /// > 0: simulate on the prone model re-tetrahedralized at this cell size [m] when the
  /// scene's mesh is finer (see simulation_scene); 0: the scene's mesh as given.
  double simulation_cell_size = 0;
  /// The preset's volume form, taken by RegistrationEngine where the scene's material.volume_form
  /// is `auto` and the scene plans the unloaded shape (prone_gravity): Nodal registers such a scene
  /// with the nodal form, on the mesh nodal_simulation_cell_size gives. An explicit element or
  /// nodal in the scene wins; Auto (and Element, which no preset needs: Poisson's ratio gives the
  /// element form at the thesis's nu) leaves the form to Poisson's ratio (kNodalVolumeFromPoisson).
  /// Only unloading scenes: with the prone shape as the rest shape on soft tissue the nodal form
  /// folds the mesh and ends farther off (BENCHMARKS.md, "The nodal volume term as the default").
  VolumeForm volume_form = VolumeForm::Auto;
  /// The preset's elements for the unloaded shape, taken with its nodal form (where
  /// takes_preset_volume_form) when the scene does not state material.unload_element_order
  /// (preset_unload_elements). Balanced and accurate: quadratic (BENCHMARKS.md, "The quadratic
  /// unload as the balanced preset's default"; "The accurate preset on balanced's model, and the
  /// unload's 4-point rule").
  ElementOrder unload_element_order = ElementOrder::Linear;
  /// > 0: the simulation cell size [m] where the preset's nodal form is taken (the nodal form is
  /// the costlier per tetrahedron and locks less, so its point on the front is a coarser mesh)
  double nodal_simulation_cell_size = 0;
  /// > 0: where a call meshes the prone model, cells of at most this size [m] in each tumour's
  /// bounding ball, graded to the call's size (tumour_refinements), unless the scene states
  /// prone.tumour_cell_size_mm (tumour_cell_size_for). Accurate: 4 mm (2026-12-07, seventh
  /// session, over five mesh draws: the stiff tumours' axis ratio nearer the truth on all six
  /// resolved truths, the worst tumour nearer on five; BENCHMARKS.md, "Finer cells around the
  /// tumours in the accurate preset"); fast and balanced: none.
  double tumour_cell_size = 0;
  /// A rigid alignment found elsewhere (e.g. the ROS node's ICP tracking of the depth
  /// camera): supine -> model. When set, the rigid step uses it instead of Kabsch and ICP.
  std::optional<Rigid> known_supine_to_model;
  /// How well known_supine_to_model is known: the covariance of a small motion xi = (omega
  /// [rad], tau [m]) applied after it in the model frame (IcpResult::pose_covariance's
  /// convention). The linear region takes it as the source rigid_pose and sampling draws the
  /// pose from it; empty: the pose is held.
  std::optional<Mat6> known_pose_covariance;
  /// [m] When ICP on the rigid regions decides the pose and the pose solved jointly with the
  /// landmarks moves the rigid region by more than this, the result carries a warning.
  double pose_disagreement_warning = 0.003;
  /// Plausibility of the result (a result far from its own data is not an answer, whatever
  /// the solver's verdict): it is flagged `implausible`, with a warning, when the largest
  /// landmark residual (when the landmark step ran) exceeds max(landmark_residual_bound, landmark_residual_fraction x the
  /// prone model's bounding-box diagonal), or the mean distance of the skin to the supine
  /// surface exceeds max(skin_distance_bound, skin_distance_fraction x that diagonal).
  /// Chosen on two bodies (BENCHMARKS.md): far above what converged runs show, below a
  /// model that cannot follow its data (locked, far too stiff) or a flipped pose.
  double landmark_residual_bound = 0.005;      ///< [m]
  double landmark_residual_fraction = 0.02;
  double skin_distance_bound = 0.002;          ///< [m]
  double skin_distance_fraction = 0.01;
  /// The tumours' linearised uncertainty (tumour_uncertainty.h), when enabled and the surface step ran.
  UncertaintyOptions uncertainty;
};

/// Whether a registration of `scene` with `opt` takes the preset's nodal volume form
/// (RegistrationOptions::volume_form): the scene's form is auto, it plans the unloaded shape, and
/// the preset asks for the nodal form.
bool takes_preset_volume_form(const Scene& scene, const RegistrationOptions& opt);

/// The simulation cell size [m] a registration of `scene` with `opt` asks for: the preset's
/// nodal_simulation_cell_size where it takes its nodal form (takes_preset_volume_form), else
/// opt.simulation_cell_size (0: the scene's mesh as given). A mesh made at this size is simulated
/// as it is (RegistrationEngine, btr_scene_from_labels).
double simulation_cell_size_for(const Scene& scene, const RegistrationOptions& opt);

/// The tumour cell size [m] a call meshes the prone model with: the scene's
/// prone.tumour_cell_size_mm where stated (0: none), else opt.tumour_cell_size.
double tumour_cell_size_for(const Scene& scene, const RegistrationOptions& opt);

/// The elements `scene` is unloaded with in a registration with `opt`: the preset's
/// (RegistrationOptions::unload_element_order) where it takes its nodal form and the scene does
/// not state them, else the scene's material.unload_element_order.
ElementOrder preset_unload_elements(const Scene& scene, const RegistrationOptions& opt);

/// Options of a preset: "fast", "balanced" or "accurate" (see BENCHMARKS.md for the
/// measured speed and accuracy of each). Throws InputError for another name.
RegistrationOptions preset_options(const std::string& name);

struct PlannedSteps {
  bool rigid_landmarks = false;  ///< Kabsch on >= 3 landmark pairs (first guess; the landmark step then solves the pose)
  bool rigid_icp = false;        ///< ICP on prone and supine rigid regions
  bool stiffness = false;        ///< Young's modulus estimated from the data (youngs_modulus: estimate), before unload
  bool unload = false;           ///< the rest shape is the unloaded shape estimated from the prone one (scene.prone_gravity)
  bool gravity = false;
  bool landmarks = false;
  bool surface = false;
  std::string describe() const;
};

/// Steps for the scene: `auto` (scene.steps empty) takes every step its inputs allow
/// (rigid when it has >= 3 landmarks or both rigid regions; landmarks; surface). An
/// explicit list is checked against the inputs; a missing input is an InputError naming
/// the field. `unload` is planned exactly when the scene gives prone_gravity and the plan
/// simulates (plan_simulates), listed or not: it changes the model every other step simulates,
/// not the data they fit. `stiffness` is planned exactly when the scene says
/// `youngs_modulus: estimate` and the plan simulates, and needs prone_gravity and >= 3 landmarks.
PlannedSteps plan_steps(const Scene& scene);
/// Whether the scene's steps simulate (gravity, landmarks or surface): only they read the rest
/// shape and the material, so a plan of rigid alignment alone neither estimates the stiffness
/// nor unloads (before: a rigid-only run of the suite on a 300 Pa body spent 129 s estimating E).
bool plan_simulates(const Scene& scene);
/// Whether the model is unloaded when it is prepared (prepare_model): the plan unloads and
/// does not estimate the stiffness (which unloads per candidate instead).
bool unloads_in_preparation(const Scene& scene);

/// When opt.simulation_cell_size asks for a clearly coarser mesh than the scene's (mean edge
/// below 1.1 cell sizes; a mesh made at that size has about 1.35): the scene with its prone model re-tetrahedralized
/// (with_simulation_mesh); otherwise nullopt (simulate on the scene's mesh). Callers
/// prepare it once and cache it with its model.
std::optional<Scene> simulation_scene(const Scene& scene, const RegistrationOptions& opt);
/// Whether simulation_scene would re-tetrahedralize (without doing it).
bool needs_simulation_mesh(const Scene& scene, const RegistrationOptions& opt);

/// Builds the registration model of a scene (material, tumours embedded, stiffer tumour if
/// asked, and the unloaded rest shape when the scene gives prone_gravity: model.unload, whose
/// report every run_registration result carries; with `youngs_modulus: estimate` the unload
/// waits for the stiffness, and runs in run_registration). `warnings` receives messages about tumour
/// points outside the mesh. `cache`: the engine's solvers, which the unload's forward solves use.
RegistrationModel prepare_model(const Scene& scene, std::vector<std::string>& warnings, const UnloadOptions& unload = {},
                                StepSolvers* cache = nullptr);

struct TumourResult {
  std::string name;
  SurfaceMesh registered;   ///< supine frame
  Vec3 centroid;            ///< supine frame [m]
  double volume_ratio = 0;  ///< registered volume / prone volume
  double axis_ratio = 0;    ///< shortest / longest principal axis of the registered tumour
  double prone_axis_ratio = 0;  ///< the same for the prone tumour (flattening: axis_ratio < prone_axis_ratio)
  bool has_ground_truth = false;
  double centroid_distance = 0;  ///< [m] to the ground-truth centroid
  double hausdorff = 0;          ///< [m]
  double volume_ratio_to_truth = 0;
  double truth_axis_ratio = 0;
  double rigid_centroid_distance = 0;  ///< [m] prone tumour (rigidly aligned) to ground truth
  std::optional<TumourUncertainty> uncertainty;  ///< when asked for (RegistrationOptions::uncertainty)
};

struct RegistrationResult {
  PlannedSteps steps;
  Rigid supine_to_model = Rigid::Identity();  ///< the rigid alignment found
  bool icp_used = false;
  IcpResult icp;
  bool pose_solved_with_landmarks = false;  ///< the landmark step solved the pose (no decisive ICP)
  bool pose_solved_with_surface = false;    ///< the surface step refined it (no decisive ICP)
  /// There: the landmark targets it moved onto the supine surface (SurfaceStepOptions::landmarks_on_scan)
  int landmarks_moved_onto_scan = 0;
  int rigid_distinct_poses = 0;       ///< distinct poses the rigid regions fit equally well (> 1: symmetric)
  bool rigid_decided_by_landmarks = false;  ///< several of them, and the landmarks chose
  bool rigid_pose_undecided = false;  ///< several of them and nothing told them apart (a warning says so)
  std::string rigid_note;             ///< what the symmetry check found (empty: one pose fits)
  double pose_disagreement = 0;  ///< [m] ICP vs joint landmark pose, max over the rigid region (when both ran)
  double rigid_seconds = 0;
  /// [Pa] the stiffness step's estimate (0: not estimated); the steps simulated with every
  /// material scaled to it
  double estimated_youngs_modulus = 0;
  std::vector<StiffnessCandidate> stiffness_evaluations;  ///< the candidates it tried, in order
  /// The sd of ln E about the estimate, from the landmarks' sd (the uncertainty sources') and
  /// how the misfit moves with E (StiffnessEstimate::log_sd); 0: not known or not estimated
  double estimated_youngs_modulus_log_sd = 0;
  /// The stiffness step's supine gravity-only prediction at the estimate (model frame [m];
  /// empty: not estimated): StiffnessEstimate::supine_prediction
  Points stiffness_prediction;
  std::vector<StepReport> reports;
  /// The volume term the result was computed with (the model's, resolved from `auto`)
  VolumeForm volume_form = VolumeForm::Element;
  /// Set where a registration with the nodal form ended not converged and the engine registered
  /// again with the element form (Scene::nodal_fallback): this result is the element form's.
  struct VolumeFormFallback {
    std::string nodal_stop;      ///< the nodal attempt's unconverged steps and their stop reasons
    double nodal_seconds = 0;    ///< its registration time [s] (in `seconds`)
    double prepare_seconds = 0;  ///< preparing the element form's model (first fallback only; in `seconds`)
    /// Where the nodal form was the preset's (RegistrationOptions::volume_form), the element form
    /// runs on the mesh the preset simulates it on, as if the preset had not taken the nodal form:
    /// how that mesh was made ("re-tetrahedralized the prone model at 7.0 mm", or "the scene's
    /// mesh"); empty where the fallback ran on the nodal attempt's own mesh.
    std::string mesh_note;
  };
  std::optional<VolumeFormFallback> volume_form_fallback;
  /// [m] the supine mesh's estimated noise along its normals (0: not estimated: no mesh, or
  /// denoising off), and whether the surface step projected onto it denoised
  double supine_noise = 0;
  bool supine_denoised = false;
  Points x;                 ///< deformed vertex positions, model frame
  double seconds = 0;       ///< all steps, rigid alignment included
  std::vector<TumourResult> tumours;
  double landmark_residual_mean = 0, landmark_residual_max = 0;  ///< [m]
  /// [m] to the supine surface as the surface step saw it (denoised where supine_denoised)
  double skin_distance_mean = 0, skin_distance_max = 0;
  bool converged = true;
  /// The result is far from its own data (see RegistrationOptions' plausibility bounds) or
  /// the rigid pose was left undecided; `warnings` says which. btr_register exits with 5.
  bool implausible = false;
  std::vector<std::string> warnings;
  std::string uncertainty_note;    ///< what the uncertainty assumed, or why it was not computed
  double uncertainty_seconds = 0;  ///< its cost, not in `seconds`
  /// Filled by a caller that sampled (RegistrationEngine::sample_uncertainty), for the report.
  std::optional<SampledUncertainty> sampled_uncertainty;
};

/// Runs the planned steps. Throws InputError for inconsistent inputs and SolverError for
/// numerical failure; a step that stops without converging sets `converged = false`.
/// cache: the solvers kept for `prepared` between calls (RegistrationEngine does this);
/// nullptr builds every step's solver for this call. The answer is the same either way.
RegistrationResult run_registration(const Scene& scene, const RegistrationModel& prepared, const RegistrationOptions& opt,
                                    const StepCallback& callback = {}, StepSolvers* cache = nullptr);

}  // namespace btr
