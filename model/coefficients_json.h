#pragma once
/// The coefficient file of `rlgtherm fit` (SPEC section 3), read back by `compensate`.

#include <nlohmann/json.hpp>
#include <string>

#include "model/guo2006.h"

namespace rlg::model {

nlohmann::json ToJson(const Guo2006Coefficients& c);
/// InputError naming `source` and the missing or malformed key.
Guo2006Coefficients CoefficientsFromJson(const nlohmann::json& j, const std::string& source);
Guo2006Coefficients ReadCoefficientsFile(const std::string& path);

}  // namespace rlg::model
