#include "breast_tumour_registration/fem/element_order.h"

#include "breast_tumour_registration/base/errors.h"

namespace btr {

ElementOrder parse_element_order(const std::string& s) {
  if (s == "linear") return ElementOrder::Linear;
  if (s == "quadratic") return ElementOrder::Quadratic;
  throw InputError("element order must be 'linear' or 'quadratic', not '" + s + "'");
}

const char* to_string(ElementOrder order) { return order == ElementOrder::Quadratic ? "quadratic" : "linear"; }

}  // namespace btr
