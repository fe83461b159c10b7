// The polynomial order of the tetrahedra a simulation uses: linear (4 nodes, the thesis's) or
// quadratic (10 nodes, quadratic_tetrahedra.h). A choice a scene may state for the unloaded
// shape (material.unload_element_order).
#pragma once

#include <string>

namespace btr {

enum class ElementOrder { Linear, Quadratic };
/// Parses "linear" or "quadratic"; InputError otherwise.
ElementOrder parse_element_order(const std::string& s);
const char* to_string(ElementOrder order);

}  // namespace btr
