// Which material each tetrahedron has: the per-tetrahedron index list the elastic terms take,
// checked once in one place.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

namespace btr {

/// material_of checked against `materials` materials and `tetrahedra` tetrahedra and returned
/// (empty: every tetrahedron has material 0). InputError prefixed with `who` for no material,
/// a wrong length, or an index out of range.
std::vector<int> checked_material_of(std::vector<int> material_of, size_t materials, Eigen::Index tetrahedra,
                                     const std::string& who);

}  // namespace btr
