// Command-line checks shared by the package's tools: numbers that must be finite (CLI11's own
// range checks let NaN through: NaN < 0 is false), and one exit code for every command-line
// mistake, the tools' documented 2 for invalid input (CLI11 uses 105 to 109).
#pragma once

#include <CLI/CLI.hpp>

#include <cmath>
#include <string>

namespace btr::cli {

inline CLI::Validator finite_at_least(double lo, bool inclusive, const std::string& what) {
  return CLI::Validator(
      [=](std::string& s) -> std::string {
        double v = 0;
        try {
          size_t used = 0;
          v = std::stod(s, &used);
          if (used != s.size()) return "'" + s + "' is not a number";
        } catch (const std::exception&) {
          return "'" + s + "' is not a number";
        }
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
