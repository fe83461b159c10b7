// Small text helpers shared by the file readers (extensions, case-insensitive keys).
#pragma once

#include <optional>
#include <string>
#include <string_view>

namespace btr {

/// `s` in lower case (ASCII).
std::string lower_case(std::string s);
/// Whether `s` ends with `suffix` (case-sensitive).
bool ends_with(const std::string& s, const std::string& suffix);
/// `s` as one unquoted CSV field: commas, quotes and line breaks become ';'.
std::string csv_field(std::string s);

/// The whole of `s` as a number, through std::from_chars (locale-free; one leading '+' is
/// allowed, as files written by other tools have it; "inf" and "nan" parse, callers that need
/// finite values check). nullopt for anything else, including trailing text and out-of-range
/// values (overflow and denormal underflow).
std::optional<double> parse_number(std::string_view s);
/// The whole of `s` as an integer that fits an int; nullopt otherwise (no wrap-around).
std::optional<int> parse_integer(std::string_view s);

}  // namespace btr
