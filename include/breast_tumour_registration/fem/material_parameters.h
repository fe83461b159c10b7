// The body's material as a scene states it: the stable neo-Hookean solid (stable_neo_hookean.h)
// by Young's modulus and Poisson's ratio, its density, and the form of its volume term.
#pragma once

#include "breast_tumour_registration/fem/volume_form.h"

namespace btr {

struct MaterialParameters {
  double youngs_modulus = 3400;  ///< [Pa] (thesis: Hipwell et al. 2016)
  double poisson_ratio = 0.49;
  double density = 1000;         ///< [kg/m^3]
  VolumeForm volume_form = VolumeForm::Auto;  ///< element or nodal volume term (elastic_energy.h)
};

}  // namespace btr
