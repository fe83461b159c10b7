#include "breast_tumour_registration/base/units.h"

#include <cstdio>

#include <algorithm>
#include <cctype>

#include "breast_tumour_registration/base/errors.h"
#include "breast_tumour_registration/base/strings.h"

namespace btr {

double metres_per_unit(LengthUnit u) { return u == LengthUnit::Metre ? 1.0 : 1e-3; }

LengthUnit parse_length_unit(const std::string& s) {
  const std::string t = lower_case(s);
  if (t == "m" || t == "metre" || t == "meter" || t == "metres" || t == "meters") return LengthUnit::Metre;
  if (t == "mm" || t == "millimetre" || t == "millimeter" || t == "millimetres" || t == "millimeters")
    return LengthUnit::Millimetre;
  throw InputError("unknown length unit '" + s + "' (expected 'm' or 'mm')");
}

std::string to_string(LengthUnit u) { return u == LengthUnit::Metre ? "m" : "mm"; }

std::string format_mm(double metres, int decimals) {
  char b[48];
  std::snprintf(b, sizeof b, "%.*f mm", decimals, metres * 1e3);
  return b;
}

}  // namespace btr
