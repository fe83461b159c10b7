// The registration engine: one scene prepared once and registered many times. It owns, per
// simulation mesh a preset asks for, the prepared prone side (the mesh, tetrahedralized or
// re-tetrahedralized once; the model with its materials, embedded tumours and rest shape) and
// the solvers of every step (StepSolvers: Hessian patterns with CHOLMOD's symbolic analysis,
// the landmark subspace). Every caller registers through it: btr_register, the experiment
// suite, the benches and the ROS node (with solve_live on the latest depth scan).
//
// Not thread-safe: one solve at a time (the node serialises its service calls).
#pragma once

#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <tuple>
#include <vector>

#include "breast_tumour_registration/io/scene.h"
#include "breast_tumour_registration/registration/live_scene.h"
#include "breast_tumour_registration/registration/registration_pipeline.h"
#include "breast_tumour_registration/registration/step_solvers.h"
#include "breast_tumour_registration/registration/unload_step.h"

namespace btr {

/// A scene's prone side prepared for one simulation mesh.
struct PreparedScene {
  Scene scene;                        ///< as simulated: the simulation mesh, the supine side as given
  RegistrationModel model;
  std::vector<std::string> warnings;  ///< from preparing (tumour points outside the mesh, ...)
  /// How the simulation mesh was made: "tetrahedralized the prone surface at 7.0 mm",
  /// "re-tetrahedralized at 7.0 mm", or empty (the scene's mesh as given).
  std::string mesh_note;
  double mesh_seconds = 0;      ///< tetrahedralization [s]
  double prepare_seconds = 0;   ///< meshing and model preparation [s]
};

class RegistrationEngine {
 public:
  /// The scene as loaded (a prone surface may still be unmeshed: load_scene with
  /// tetrahedralize = false); nothing is prepared until the first call asks for a mesh.
  explicit RegistrationEngine(Scene scene, UnloadOptions unload = {});
  /// Adopts a model already prepared for `simulated` (e.g. the experiment suite's, whose
  /// unloaded shape is shared between runs); every call simulates on it, whatever the preset's mesh.
  RegistrationEngine(Scene simulated, RegistrationModel model, std::vector<std::string> warnings = {});

  /// The prone side for opt's simulation mesh and volume form: a prone surface is tetrahedralized
  /// at its prone.cell_size_mm, else the preset's size; a finer scene mesh is re-tetrahedralized at
  /// the preset's size (simulation_scene); the model is prepared with the scene's volume form, or
  /// the preset's nodal form where the scene unloads and says auto (takes_preset_volume_form, on
  /// the preset's mesh for it). Done on first use and kept.
  /// InputError / SolverError as load_scene, mesh_prone and prepare_model.
  const PreparedScene& prepare(const RegistrationOptions& opt);

  /// Registers the scene's own supine side. The result's warnings start with the preparation's.
  /// Every solve (not the samples' re-registrations) with the nodal volume form that ends not
  /// converged is run again with the element form where the scene allows it
  /// (Scene::nodal_fallback, the default), and the element form's result is returned with
  /// RegistrationResult::volume_form_fallback set and a warning: on coarse soft meshes the nodal
  /// form folds where the element form holds (BENCHMARKS.md, "The fallback to the element form").
  /// The element form runs on the same mesh where the scene chose the nodal form, and on the
  /// preset's element mesh where the preset did (the call as it would be without the preset's
  /// nodal form: balanced's 7 mm, not its nodal 9 mm, so a fallback is never coarser than the
  /// element form's own default).
  RegistrationResult solve(const RegistrationOptions& opt, const StepCallback& callback = {});
  /// Registers `supine` (this engine's scene, or a copy whose supine side, landmarks' supine
  /// positions, ground truth or steps were replaced) on the prepared prone side; InputError when
  /// its prone side is not this engine's (another vertex or landmark count).
  RegistrationResult solve(const Scene& supine, const RegistrationOptions& opt, const StepCallback& callback = {});
  /// Registers a live depth scan (live_scene): the tracked pose decides the rigid alignment.
  RegistrationResult solve_live(const LiveScan& scan, const LiveSceneOptions& live, RegistrationOptions opt,
                                const StepCallback& callback = {});

  /// Registers the scene `samples` times with its inputs drawn from `sources.sources` (seeded;
  /// uncertainty_sources.h: E log-uniform over its range, Poisson's ratio uniform, the gravity
  /// tilt about both horizontal axes, every supine landmark, and depth noise along the supine
  /// surface's vertex normals, independent per vertex), on the prepared mesh with the kept
  /// solvers; `nominal` is this engine's solve(opt). On an unloaded model every sample that
  /// draws a material estimates the unloaded shape again. E is not sampled where the scene
  /// estimates it (the stiffness step does, from the sampled landmarks), and the noise not on a
  /// point cloud; the note says so. The samples use the volume form `nominal` was computed
  /// with (the element form where it fell back) and do not fall back one by one. With the
  /// discretisation source (on by default) and the element form, the nominal inputs are
  /// registered once more with the nodal form, and the region takes that shift as the element
  /// form's own error (SampledUncertainty::Tumour::discretisation).
  SampledUncertainty sample_uncertainty(const RegistrationOptions& opt, const UncertaintyOptions& sources, int samples,
                                        unsigned seed, const RegistrationResult& nominal);

  /// The same for a live depth scan (solve_live's scene); `nominal` is this engine's
  /// solve_live(scan, live, opt).
  SampledUncertainty sample_uncertainty_live(const LiveScan& scan, const LiveSceneOptions& live, RegistrationOptions opt,
                                             const UncertaintyOptions& sources, int samples, unsigned seed,
                                             const RegistrationResult& nominal);

  /// The prepared scene a result of solve(opt, ...) or solve_live was computed on: prepare(opt),
  /// or where it fell back to the element form, the entry that form ran on (another mesh where
  /// the nodal form was the preset's). Its model is the one to write the result with.
  const PreparedScene& prepared_for(const RegistrationOptions& opt, const RegistrationResult& r);

  const Scene& scene() const { return scene_; }  ///< as given
  int solvers_built() const;   ///< over every prepared mesh
  int solvers_reused() const;

 private:
  struct Entry {
    PreparedScene prepared;
    StepSolvers solvers;
    /// The same mesh prepared with the other volume form (its own unloaded shape and solvers),
    /// made on first use: the element form where a nodal registration falls back to it, the
    /// nodal form where sampling estimates the element form's discretisation error
    std::unique_ptr<Entry> twin;
    Entry* twin_of = nullptr;  ///< the entry this one is the twin of
  };
  /// The supine scene of a call on an entry's prepared scene, and the call's options for it
  using SupineFor = std::function<Scene(const Entry&, RegistrationOptions&)>;
  /// The entry a call simulates on: opt's simulation mesh, with the preset's nodal form where the
  /// scene's volume form is auto and the scene unloads (takes_preset_volume_form; on the mesh
  /// RegistrationOptions::nodal_simulation_cell_size gives), else the scene's form as resolved;
  /// prepared on first use (the first form asked for on a mesh is its entry, the other that
  /// entry's twin)
  Entry& entry(const RegistrationOptions& opt);
  /// e itself where its model resolved to `form`, else its twin with that form (or the entry e is
  /// the twin of), prepared on first use
  Entry& twin_entry(Entry& e, VolumeForm form);
  /// The model's discretisation error as sampling takes it (UncertaintySources::discretisation):
  /// the nominal inputs (`scene`, on e's mesh) registered again with the nodal volume form; none,
  /// with a note saying why, for a nominal already nodal or fallen back, or a reference that did
  /// not converge or failed.
  std::optional<RegistrationResult> discretisation_reference(Entry& e, const Scene& scene, const RegistrationOptions& opt,
                                                             const RegistrationResult& nominal,
                                                             std::vector<std::string>& notes);
  /// Where a nodal registration on entry(opt) falls back to the element form: the preset's element
  /// mesh where the preset chose the nodal form (entry(opt) with the scene's own form), else
  /// entry(opt)'s element twin
  Entry& fallback_entry(const RegistrationOptions& opt);
  int prepared_entries() const;  ///< entries and twins
  /// The entry `nominal` was computed on: entry(opt), or its fallback_entry where it fell back
  Entry& nominal_entry(const RegistrationOptions& opt, const RegistrationResult& nominal);
  /// Registers on entry(opt) the supine scene supine_for makes; falls back as solve() says
  RegistrationResult run(const SupineFor& supine_for, const RegistrationOptions& opt, const StepCallback& callback);
  /// The scene of a live scan on `e`'s prepared scene; `opt` takes the tracked pose it decides
  /// and that pose's covariance (solve_live and sample_uncertainty_live alike).
  static Scene live_call(const Entry& e, const LiveScan& scan, const LiveSceneOptions& live, RegistrationOptions& opt);
  /// Sampling on `scene` (the prepared scene with the call's supine side).
  SampledUncertainty sample(Entry& e, const Scene& scene, const RegistrationOptions& opt, const UncertaintyOptions& sources,
                            int samples, unsigned seed, const RegistrationResult& nominal);

  Scene scene_;
  UnloadOptions unload_;
  bool adopted_ = false;                           ///< one entry for every call
  /// By simulation cell size [m] (0: the scene's mesh as given), the tumour cell size it was
  /// meshed with [m] (0: none; tumour_cell_size_for) and the unload's elements
  /// (preset_unload_elements)
  std::map<std::tuple<double, double, ElementOrder>, std::unique_ptr<Entry>> entries_;
};

}  // namespace btr
