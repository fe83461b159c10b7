// Command-line checks shared by the package's tools: numbers that must be finite (CLI11's own
// range checks let NaN through: NaN < 0 is false), and one exit code for every command-line
// mistake, the tools' documented 2 for invalid input (CLI11 uses 105 to 109).
#pragma once

#include <CLI/CLI.hpp>

#include <cmath>
#include <string>

#include "breast_tumour_registration/base/strings.h"
#include "breast_tumour_registration/fem/element_order.h"

namespace btr::cli {

inline CLI::Validator finite_at_least(double lo, bool inclusive, const std::string& what) {
  return CLI::Validator(
      [=](std::string& s) -> std::string {
        const auto parsed = parse_number(s);
        if (!parsed) return "'" + s + "' is not a number";
        const double v = *parsed;
        if (!std::isfinite(v)) return "'" + s + "' is not finite";
        if (inclusive ? v < lo : v <= lo) return "'" + s + "' must be " + what;
        return std::string();
      },
      what);
}
/// > 0 and finite.
inline CLI::Validator positive() { return finite_at_least(0.0, false, "a finite number > 0"); }
/// >= 0 and finite.
inline CLI::Validator non_negative() { return finite_at_least(0.0, true, "a finite number >= 0"); }

/// An option `name` taking linear or quadratic, parsed into `order` (whose value is the default).
inline CLI::Option* element_order_option(CLI::App& app, const std::string& name, ElementOrder& order,
                                         const std::string& help) {
  return app
      .add_option_function<std::string>(name, [&order](const std::string& s) { order = parse_element_order(s); }, help)
      ->check(CLI::IsMember({"linear", "quadratic"}))
      ->default_str(to_string(order));
}

/// Parses; help and version exit 0, any command-line mistake prints CLI11's message and
/// returns 2. Use as `if (int rc = btr::cli::parse(app, argc, argv); rc >= 0) return rc;`.
inline int parse(CLI::App& app, int argc, char** argv) {
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? 0 : 2;
  }
  return -1;
}

}  // namespace btr::cli
