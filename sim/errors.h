#pragma once
/// Error types shared by every rlgtherm library. The CLI maps them to exit statuses
/// (SPEC section 3): InputError -> 2 (bad usage or bad input), NumericalError -> 3
/// (solver failure, ill-conditioned fit). Messages name the file, line and what was expected.

#include <stdexcept>
#include <string>

namespace rlg {

/// Bad user input: a file, key, column or value that is missing or out of range.
class InputError : public std::runtime_error {
 public:
  explicit InputError(const std::string& what) : std::runtime_error(what) {}
};

/// A numerical failure: the integrator gave up, or a fit cannot identify its coefficients.
class NumericalError : public std::runtime_error {
 public:
  explicit NumericalError(const std::string& what) : std::runtime_error(what) {}
};

}  // namespace rlg
