// Landmark-guided deformation (thesis Sec. 4.3, Algorithm 1): soft landmark springs
// (eq. 4.2) pull the prone landmarks towards their supine positions, solved by Newton's
// method in a linear-skinning subspace seeded with the landmark vertices, chest wall fixed.
#pragma once

#include <vector>

#include "breast_tumour_registration/fem/energy_term.h"
#include "breast_tumour_registration/fem/skinning_subspace.h"
#include "breast_tumour_registration/geometry/anchor.h"
#include "breast_tumour_registration/geometry/rigid_transform.h"
#include "breast_tumour_registration/registration/registration_model.h"
#include "breast_tumour_registration/registration/step_solvers.h"

namespace btr {

struct LandmarkStepOptions {
  double weight = 1e4;        ///< landmark spring [N/m] (thesis default)
  bool gravity = true;        ///< include supine gravity (thesis Algorithm 1)
  SubspaceOptions subspace;
  NewtonOptions newton;
};

/// anchors: prone landmark points on the model; targets: supine landmark positions in the
/// model frame (rows). x: current positions, updated in place.
/// pose == nullptr: the targets stay where they are. Otherwise the targets may move rigidly
/// and their pose is solved jointly with the deformation (RigidFreeLandmarkEnergy; needs
/// >= 3 landmarks); on return *pose maps the given targets to where they ended.
/// cache: an engine's solvers for this model (the subspace and the Hessian pattern are reused
/// while unchanged); nullptr builds them for this call.
StepReport landmark_step(const RegistrationModel& model, const std::vector<Anchor>& anchors, const Points& targets,
                         const LandmarkStepOptions& opt, Points& x, const StepCallback& callback = {},
                         Rigid* pose = nullptr, StepSolvers* cache = nullptr);

}  // namespace btr
