#pragma once
/// The coefficient file of `rlgtherm fit` (docs/data-format.md), read back by `compensate`: one
/// file for every member of the model family (model/compensation_model.h). Its "model" key says
/// which: "guo2006" (Eq. (2); a file without the key is Eq. (2) too) or "poly".

#include <nlohmann/json.hpp>
#include <string>
#include <string_view>

#include "model/compensation_model.h"
#include "model/guo2006.h"
#include "model/poly_model.h"

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

nlohmann::json ToJson(const PolyModel& m);
nlohmann::json ModelToJson(const FittedModel& m);
/// Any model's file: "model": "poly" is read as a polynomial model, anything else by the Eq. (2)
/// reader above (so Eq. (2) files read as they always have). Refused besides wrong types, for a
/// polynomial: an order outside 1..5, an unknown offset or term, a reversed or implausible range
/// or reference, terms whose time constants or widths lie outside the physical limits, a
/// gradient to the channel itself or named twice, coefficients that are not the model's in name
/// or number, and a coefficient so large that its term alone would exceed the bias limit for
/// temperatures (and rates up to 100 °C/min) the data can hold: within them every compensated
/// value is finite.
FittedModel ModelFromJson(const nlohmann::json& j, const std::string& source);
FittedModel ParseModel(std::string_view text, const std::string& source);
FittedModel ReadModelFile(const std::string& path);

}  // namespace rlg::model
