// Exceptions thrown by the core library. The host (command-line tool, ROS node)
// decides how to report them; the library never prints and never exits.
#pragma once

#include <stdexcept>
#include <string>

namespace btr {

/// Bad input: a missing or malformed file, an index out of range, an invalid mesh,
/// a parameter out of range. The message says what is wrong and where.
class InputError : public std::runtime_error {
 public:
  explicit InputError(const std::string& what) : std::runtime_error(what) {}
};

/// A numerical failure the caller may want to distinguish from bad input
/// (a factorization that cannot be repaired, a non-finite energy).
class SolverError : public std::runtime_error {
 public:
  explicit SolverError(const std::string& what) : std::runtime_error(what) {}
};

}  // namespace btr
