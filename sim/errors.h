#pragma once
/// Error types shared by every rlgtherm library. The CLI maps them to exit statuses
/// (docs/cli.md): InputError -> 2 (bad usage or bad input), NumericalError -> 3
/// (solver failure, ill-conditioned fit), OutputError -> 1. Messages name the file, line and
/// what was expected.

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

/// Writing an output failed on a usable path (disk full, file size limit, I/O error): neither
/// bad usage nor bad input, so exit status 1, with the file and the system's reason.
class OutputError : public std::runtime_error {
 public:
  explicit OutputError(const std::string& what) : std::runtime_error(what) {}
};

}  // namespace rlg
