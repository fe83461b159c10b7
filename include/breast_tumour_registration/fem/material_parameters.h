// The body's material as a scene states it: the stable neo-Hookean solid (stable_neo_hookean.h)
// by Young's modulus and Poisson's ratio, its density, and the form of its volume term.
#pragma once

#include "breast_tumour_registration/fem/element_order.h"
#include "breast_tumour_registration/fem/volume_form.h"

namespace btr {

struct MaterialParameters {
  double youngs_modulus = 3400;  ///< [Pa] (thesis: Hipwell et al. 2016)
  double poisson_ratio = 0.49;
  double density = 1000;         ///< [kg/m^3]
  VolumeForm volume_form = VolumeForm::Auto;  ///< element or nodal volume term (elastic_energy.h)
  /// With the nodal volume term: the volume stiffness every tetrahedron keeps on its own J, in
  /// units of its mu (at most its lambda; nodal_volume_energy.h). 0: the plain nodal form. A
  /// trade (BENCHMARKS.md, "The nodal form with an element share"): 5 converges more of the
  /// suite's soft runs and costs 0.1 to 0.2 mm at fat 1000 Pa.
  double nodal_element_share = 0;
  /// The elements of the unloaded-shape estimate (the forward model the unload inverts; the
  /// registration steps stay linear, and the stiffness search compares its candidates with
  /// linear elements, then unloads the chosen E with these). Quadratic: measured against SfePy's
  /// cubic truth (BENCHMARKS.md, "A quadratic forward model for the unload"), at several times
  /// the unload's cost. The quadratic shape is found from the linear one (unload_step.h).
  ElementOrder unload_element_order = ElementOrder::Linear;
};

}  // namespace btr
