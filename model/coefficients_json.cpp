#include "model/coefficients_json.h"

#include <cmath>
#include <filesystem>
#include <fmt/format.h>
#include <fstream>

#include "sim/errors.h"

namespace rlg::model {

nlohmann::json ToJson(const Guo2006Coefficients& c) {
  nlohmann::json A = nlohmann::json::array(), se = nlohmann::json::array();
  for (int k = 0; k < 3; ++k) {
    A.push_back({c.A(k, 0), c.A(k, 1), c.A(k, 2)});
    se.push_back({c.A_stderr(k, 0), c.A_stderr(k, 1), c.A_stderr(k, 2)});
  }
  return {{"model", "guo2006"},
          {"pair", {c.pair[0], c.pair[1]}},
          {"B0_window_s", c.b0_window_s},
          {"A", A},
          {"A_stderr", se},
          {"T10_range_C", {c.t10_range_C[0], c.t10_range_C[1]}},
          {"condition_number", c.condition_number},
          {"residual_rms_dph", c.residual_rms_dph},
          {"method", c.method},
          {"runs", c.runs}};
}

Guo2006Coefficients CoefficientsFromJson(const nlohmann::json& j, const std::string& source) {
  auto fail = [&](const std::string& what) -> void {
    throw InputError(fmt::format("{}: {} (expected the JSON written by 'rlgtherm fit')", source, what));
  };
  auto number = [&](const nlohmann::json& v, const std::string& key) {
    if (!v.is_number() || !std::isfinite(v.get<double>())) fail(fmt::format("'{}' must hold finite numbers", key));
    return v.get<double>();
  };
  if (!j.is_object()) fail("not a JSON object");
  if (j.value("model", "") != "guo2006") fail("key 'model' must be \"guo2006\"");
  for (const char* key : {"pair", "B0_window_s", "A", "T10_range_C"})
    if (!j.contains(key)) fail(fmt::format("missing key '{}'", key));
  Guo2006Coefficients c;
  const auto& pair = j["pair"];
  if (!pair.is_array() || pair.size() != 2 || !pair[0].is_string() || !pair[1].is_string()) {
    fail("'pair' must be two channel names, e.g. [\"T1\",\"T2\"]");
  }
  c.pair = {pair[0].get<std::string>(), pair[1].get<std::string>()};
  c.b0_window_s = number(j["B0_window_s"], "B0_window_s");
  if (!(c.b0_window_s > 0.0)) fail("'B0_window_s' must be positive");
  const auto& A = j["A"];
  if (!A.is_array() || A.size() != 3) fail("'A' must be a 3x3 array [[A10,A11,A12],[A20,..],[A30,..]]");
  for (int k = 0; k < 3; ++k) {
    if (!A[k].is_array() || A[k].size() != 3) fail("'A' must be a 3x3 array");
    for (int l = 0; l < 3; ++l) c.A(k, l) = number(A[k][l], "A");
  }
  const auto& range = j["T10_range_C"];
  if (!range.is_array() || range.size() != 2) fail("'T10_range_C' must be [min, max]");
  c.t10_range_C = {number(range[0], "T10_range_C"), number(range[1], "T10_range_C")};
  c.condition_number = j.contains("condition_number") ? number(j["condition_number"], "condition_number") : 0.0;
  c.residual_rms_dph = j.contains("residual_rms_dph") ? number(j["residual_rms_dph"], "residual_rms_dph") : 0.0;
  c.method = j.value("method", "joint");
  if (j.contains("runs") && j["runs"].is_array())
    for (const auto& r : j["runs"]) c.runs.push_back(r.get<std::string>());
  return c;
}

Guo2006Coefficients ReadCoefficientsFile(const std::string& path) {
  std::ifstream in(path);
  if (!std::filesystem::is_regular_file(path) || !in) throw InputError(fmt::format("{}: cannot open coefficient file", path));
  nlohmann::json j;
  try {
    in >> j;
  } catch (const nlohmann::json::parse_error& e) {
    throw InputError(fmt::format("{}: not valid JSON: {}", path, e.what()));
  }
  return CoefficientsFromJson(j, path);
}

}  // namespace rlg::model
