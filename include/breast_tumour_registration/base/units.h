// Length units of files. Conversion happens once, when a file is read or written.
#pragma once

#include <string>

namespace btr {

enum class LengthUnit { Metre, Millimetre };

/// Metres per file unit (1 for m, 1e-3 for mm).
double metres_per_unit(LengthUnit u);
/// Parses "m" / "metre" / "meter" / "mm" / "millimetre" / "millimeter"; throws InputError otherwise.
LengthUnit parse_length_unit(const std::string& s);
std::string to_string(LengthUnit u);

/// A length [m] for messages, in millimetres: format_mm(0.00123) is "1.2 mm".
std::string format_mm(double metres, int decimals = 1);

}  // namespace btr
