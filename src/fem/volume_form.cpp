#include "breast_tumour_registration/fem/volume_form.h"

#include "breast_tumour_registration/base/errors.h"

namespace btr {

VolumeForm resolve_volume_form(VolumeForm form, double poisson_ratio) {
  if (form != VolumeForm::Auto) return form;
  return poisson_ratio >= kNodalVolumeFromPoisson ? VolumeForm::Nodal : VolumeForm::Element;
}

VolumeForm parse_volume_form(const std::string& s) {
  if (s == "auto") return VolumeForm::Auto;
  if (s == "element") return VolumeForm::Element;
  if (s == "nodal") return VolumeForm::Nodal;
  throw InputError("volume form '" + s + "': expected auto, element or nodal");
}

const char* to_string(VolumeForm form) {
  switch (form) {
    case VolumeForm::Auto: return "auto";
    case VolumeForm::Element: return "element";
    case VolumeForm::Nodal: return "nodal";
  }
  return "?";
}

}  // namespace btr
