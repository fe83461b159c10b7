#include "breast_tumour_registration/registration/fold_advice.h"

namespace btr {

std::string fold_advice(const RegistrationModel& model, const std::vector<StepReport>& reports) {
  if (model.volume_form != VolumeForm::Nodal) return {};
  bool folded = false;
  for (const auto& rep : reports)
    folded = folded || (!rep.converged && (rep.inverted > 0 || rep.stop_reason.find("folded") != std::string::npos));
  if (!folded) return {};
  // The engine registers such a result again with the element form unless the scene says
  // `material.nodal_fallback: false`, so the advice is read where the fallback was turned off.
  const std::string where = "; `material.nodal_fallback: true` (the default) registers again with the element form "
                            "(BENCHMARKS.md, \"The nodal form with an element share\")";
  if (model.material.nodal_element_share == 0)
    return "the mesh folded under the nodal volume term: `material.nodal_element_share: 5` holds more such meshes "
           "together (on SfePy's second body 2 of 28 soft runs not converged instead of 21, at 0.1 to 0.2 mm more "
           "error where the plain form converges), `material.volume_form: element` most; a finer mesh also helps" +
           where;
  return "the mesh folded under the nodal volume term with an element share of " +
         std::to_string(model.material.nodal_element_share) +
         " mu: `material.volume_form: element` holds most such meshes together; a finer mesh also helps" + where;
}

}  // namespace btr
