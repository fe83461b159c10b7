// Small text helpers shared by the file readers (extensions, case-insensitive keys).
#pragma once

#include <string>

namespace btr {

/// `s` in lower case (ASCII).
std::string lower_case(std::string s);
/// Whether `s` ends with `suffix` (case-sensitive).
bool ends_with(const std::string& s, const std::string& suffix);

}  // namespace btr
