#include "breast_tumour_registration/fem/material_assignment.h"

#include "breast_tumour_registration/base/errors.h"

namespace btr {

std::vector<int> checked_material_of(std::vector<int> material_of, size_t materials, Eigen::Index tetrahedra,
                                     const std::string& who) {
  if (materials == 0) throw InputError(who + ": no material given");
  if (material_of.empty()) material_of.assign(static_cast<size_t>(tetrahedra), 0);
  if (static_cast<Eigen::Index>(material_of.size()) != tetrahedra)
    throw InputError(who + ": material_of has " + std::to_string(material_of.size()) + " entries for " +
                     std::to_string(tetrahedra) + " tetrahedra");
  for (int m : material_of)
    if (m < 0 || m >= static_cast<int>(materials))
      throw InputError(who + ": material index " + std::to_string(m) + " out of range");
  return material_of;
}

}  // namespace btr
