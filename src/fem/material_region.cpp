#include "breast_tumour_registration/fem/material_region.h"

#include <cmath>

#include "breast_tumour_registration/base/errors.h"
#include "breast_tumour_registration/geometry/validation.h"

namespace btr {

void validate_material_region(const MaterialRegion& r, const std::string& where) {
  if (r.name.empty()) throw InputError(where + ": a region needs a name");
  const std::string at = where + " '" + r.name + "'";
  if (!(r.youngs_modulus > 0) || !std::isfinite(r.youngs_modulus))
    throw InputError(at + ": youngs_modulus must be a positive number of Pa");
  if (r.label.has_value() == r.surface.has_value())
    throw InputError(at + ": give exactly one of 'label' (a cell label of prone.tet_mesh) and 'surface' (a closed surface)");
  if (r.surface) validate_surface(*r.surface, at + " surface");
}

}  // namespace btr
