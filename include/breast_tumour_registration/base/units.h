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

/// A length in millimetres, in metres, correctly rounded: mm / 1000 is the double nearest the
/// length, as the literal in metres is (9 * 1e-3 is 0.009000000000000001, not 0.009). Used for
/// cell sizes, where one ulp gives CGAL another mesh: `--cell-size 9` meshed other tetrahedra
/// than the balanced preset's 0.009 m (886 against 880 vertices on SfePy's first body).
constexpr double mm_to_m(double mm) { return mm / 1000.0; }

/// A length [m] for messages, in millimetres: format_mm(0.00123) is "1.2 mm".
std::string format_mm(double metres, int decimals = 1);

}  // namespace btr
