// The registration's steps as objects behind one interface. plan_steps decides from the scene
// which steps run; planned_step_sequence turns that plan into the step objects, in order
// (stiffness, unload, rigid, gravity, landmarks, surface), and run_registration runs each on
// one StepContext: the state a registration carries from step to step. A step reads the scene
// and the options, changes the state (the deformed positions, the pose, the targets, the
// model it simulates) and appends its StepReport to the result.
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "breast_tumour_registration/geometry/surface_projector.h"
#include "breast_tumour_registration/registration/registration_pipeline.h"

namespace btr {

struct StepContext {
  StepContext(const Scene& scene, const RegistrationModel& prepared, const RegistrationOptions& opt,
              const StepCallback& callback, StepSolvers* solvers, RegistrationResult& result);

  const Scene& scene;
  const RegistrationOptions& opt;
  const StepCallback& callback;
  StepSolvers* solvers;  ///< an engine's cached solvers, or nullptr (built per step)
  RegistrationResult& result;  ///< reports, warnings, pose flags and result.x, the positions (model frame)

  /// The model the steps simulate: the prepared one, or the stiffness step's copy.
  const RegistrationModel& model() const { return estimated_ ? *estimated_ : prepared_; }
  const RegistrationModel& prepared() const { return prepared_; }
  /// Makes `m` (a copy of the prepared model at the estimated stiffness) the simulated model,
  /// and starts the positions again from its rest shape.
  void use_estimated_model(RegistrationModel m);

  Rigid supine_to_model = Rigid::Identity();  ///< the pose found so far
  Points targets;            ///< supine landmarks in the model frame, under supine_to_model
  bool joint_pose = false;   ///< the landmark step solves the pose (rigid from landmarks, no ICP has decided)
  Rigid to_projector = Rigid::Identity();  ///< model frame -> the supine projector's frame (the surface step's pose)
  /// The supine surface or cloud in the model frame as the pose now has it (AABB tree or
  /// kd-tree with normals), built on first use; a noisy supine mesh denoised first
  /// (SurfaceStepOptions::scan_denoising_min_noise; result.supine_noise says what it read).
  const SurfaceProjector* supine();

 private:
  /// Sets result.x to where the deformation starts: the rest shape, stress-free, when a step
  /// deforms (every step travels rest -> supine; from the prone shape over an unloaded rest, a
  /// soft breast would have to swing through prone -> supine); else the prone shape.
  void start_positions();
  const RegistrationModel& prepared_;
  std::optional<RegistrationModel> estimated_;
  std::unique_ptr<SurfaceProjector> supine_;
};

class RegistrationStep {
 public:
  virtual ~RegistrationStep() = default;
  virtual std::string name() const = 0;
  virtual void run(StepContext& c) const = 0;
};

/// The step objects of a plan, in the order they run. The rigid step is always there: it
/// states the pose (landmarks, ICP, a known pose, or none) that the later steps start from.
std::vector<std::unique_ptr<RegistrationStep>> planned_step_sequence(const PlannedSteps& plan);

}  // namespace btr
