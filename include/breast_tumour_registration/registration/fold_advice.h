// What to try when a registration with the nodal volume term ends not converged because the mesh
// folded: the measured alternatives, as one warning (BENCHMARKS.md, "The nodal form with an
// element share"). Coarse soft meshes fold under the nodal form, whose single tetrahedra keep
// little volume stiffness of their own; an element share or the element form holds more of them.
#pragma once

#include <string>
#include <vector>

#include "breast_tumour_registration/registration/registration_model.h"

namespace btr {

/// The advice for `model` after `reports`, or empty: only with the nodal volume form, and only
/// when a step ended not converged with tetrahedra inverted or a fold named in its stop reason.
/// A user reads it where the scene turned the engine's fallback to the element form off.
std::string fold_advice(const RegistrationModel& model, const std::vector<StepReport>& reports);

}  // namespace btr
