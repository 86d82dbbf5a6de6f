#include "model/coefficients_json.h"

#include <cmath>
#include <filesystem>
#include <fmt/format.h>
#include <fstream>

#include "sim/errors.h"

namespace rlg::model {

nlohmann::json ToJson(const Guo2006Coefficients& c) {
  auto rows = [](const Eigen::Matrix3d& M) {
    nlohmann::json out = nlohmann::json::array();
    for (int k = 0; k < 3; ++k) out.push_back({M(k, 0), M(k, 1), M(k, 2)});
    return out;
  };
  nlohmann::json j = {{"model", "guo2006"},
                      {"pair", {c.pair[0], c.pair[1]}},
                      {"B0_window_s", c.b0_window_s},
                      {"A", rows(c.A)},
                      {"A_stderr", rows(c.A_stderr)},
                      {"A_stderr_dof", rows(c.stderr_dof)},
                      {"stderr_method", c.stderr_method},
                      {"T10_range_C", {c.t10_range_C[0], c.t10_range_C[1]}},
                      {"condition_number", c.condition_number},
                      {"residual_rms_dph", c.residual_rms_dph},
                      {"method", c.method},
                      {"runs", c.runs}};
  // Coefficients read back from a file carry no error model (stderr_dof 0): no intervals then.
  if (c.stderr_dof.minCoeff() > 0.0) j["A_ci95_halfwidth"] = rows(c.ConfidenceHalfWidth(0.95));
  return j;
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
