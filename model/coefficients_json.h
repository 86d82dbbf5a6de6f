#pragma once
/// The coefficient file of `rlgtherm fit` (docs/cli.md), read back by `compensate`.

#include <nlohmann/json.hpp>
#include <string>
#include <string_view>

#include "model/guo2006.h"

namespace rlg::model {

nlohmann::json ToJson(const Guo2006Coefficients& c);
/// InputError naming `source` (and the line, when known), the missing or malformed key and what
/// was expected. Refused besides wrong types: a pair naming one channel twice, a reversed or
/// implausible T10_range_C, an unknown method, and coefficients so large that one term of Eq. (2)
/// alone would exceed the bias limit for temperatures the data can hold (sim/limits.h): within
/// them every compensated value is finite.
Guo2006Coefficients CoefficientsFromJson(const nlohmann::json& j, const std::string& source);
/// The same from the file's text: syntax errors and numbers beyond a double (1e400) name the
/// line and column; a UTF-8 byte-order mark is skipped.
Guo2006Coefficients ParseCoefficients(std::string_view text, const std::string& source);
Guo2006Coefficients ReadCoefficientsFile(const std::string& path);

}  // namespace rlg::model
