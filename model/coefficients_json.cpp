#include "model/coefficients_json.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fmt/format.h>
#include <fstream>
#include <sstream>

#include "sim/errors.h"
#include "sim/limits.h"

namespace rlg::model {

namespace {

using nlohmann::json;

/// Line (1-based) of the first `"key"` followed by a colon in `text`, 0 if there is none (an
/// escaped key, or a JSON built in memory): DOM parsing keeps no positions.
int KeyLine(std::string_view text, const std::string& key) {
  const std::string quoted = "\"" + key + "\"";
  for (size_t at = text.find(quoted); at != std::string_view::npos; at = text.find(quoted, at + 1)) {
    size_t next = at + quoted.size();
    while (next < text.size() && std::isspace(static_cast<unsigned char>(text[next]))) ++next;
    if (next < text.size() && text[next] == ':') return 1 + static_cast<int>(std::count(text.begin(), text.begin() + at, '\n'));
  }
  return 0;
}

/// A SAX consumer that only records where and why a parse failed: nlohmann's DOM parser
/// throws an out_of_range for a number like 1e400 without its position.
struct ErrorPosition : nlohmann::json_sax<json> {
  size_t byte = 0;
  std::string message;
  bool null() override { return true; }
  bool boolean(bool) override { return true; }
  bool number_integer(number_integer_t) override { return true; }
  bool number_unsigned(number_unsigned_t) override { return true; }
  bool number_float(number_float_t, const string_t&) override { return true; }
  bool string(string_t&) override { return true; }
  bool binary(binary_t&) override { return true; }
  bool start_object(std::size_t) override { return true; }
  bool key(string_t&) override { return true; }
  bool end_object() override { return true; }
  bool start_array(std::size_t) override { return true; }
  bool end_array() override { return true; }
  bool parse_error(std::size_t position, const std::string&, const nlohmann::detail::exception& e) override {
    byte = position;
    message = e.what();
    return false;
  }
};

/// "[json.exception.parse_error.101] parse error at line 1, column 5: syntax error ..." -> the part after the
/// location, which we give ourselves.
std::string Reason(std::string message) {
  const size_t bracket = message.find("] ");
  if (bracket != std::string::npos) message.erase(0, bracket + 2);
  const size_t colon = message.find(": ");
  if (message.rfind("parse error", 0) == 0 && colon != std::string::npos) message.erase(0, colon + 2);
  return message;
}

class Reader {
 public:
  Reader(const json& j, const std::string& source, std::string_view text) : j_(j), source_(source), text_(text) {}

  [[noreturn]] void Fail(const std::string& key, const std::string& what) const {
    const int line = KeyLine(text_, key);
    const std::string where = line > 0 ? fmt::format("{}:{}", source_, line) : source_;
    throw InputError(fmt::format("{}: key '{}': {} (a coefficients file as 'rlgtherm fit -o' writes it)", where, key, what));
  }
  const json& Get(const std::string& key) const {
    if (!j_.contains(key)) Fail(key, "missing");
    return j_[key];
  }
  /// A finite number within [lo, hi] at j_[key] or inside it (`element` names it, e.g. "A[1][2]").
  double Number(const std::string& key, const json& v, const std::string& element, double lo, double hi,
                const std::string& why = "") const {
    if (!v.is_number()) Fail(key, fmt::format("{} must be a number, found {}", element, v.dump()));
    const double x = v.get<double>();
    if (!(x >= lo && x <= hi)) Fail(key, fmt::format("{} = {:g} is outside {:g}...{:g}{}", element, x, lo, hi, why));
    return x;
  }
  double Number(const std::string& key, double lo, double hi) const { return Number(key, Get(key), key, lo, hi); }
  const json& Array(const std::string& key, size_t size, const std::string& expected) const {
    const json& v = Get(key);
    if (!v.is_array() || v.size() != size) Fail(key, fmt::format("expected {}, found {}", expected, v.dump()));
    return v;
  }
  std::string String(const std::string& key) const {
    const json& v = Get(key);
    if (!v.is_string()) Fail(key, fmt::format("expected a string, found {}", v.dump()));
    return v.get<std::string>();
  }

 private:
  const json& j_;
  const std::string& source_;
  std::string_view text_;
};

Guo2006Coefficients FromJson(const json& j, const std::string& source, std::string_view text) {
  using namespace sim::limits;
  if (!j.is_object()) {
    throw InputError(fmt::format("{}: expected a JSON object (a coefficients file as 'rlgtherm fit -o' writes it), found "
                                 "{}", source, j.type_name()));
  }
  const Reader r(j, source, text);
  Guo2006Coefficients c;
  if (r.String("model") != "guo2006") r.Fail("model", fmt::format("expected \"guo2006\", found {}", j["model"].dump()));

  const json& pair = r.Array("pair", 2, "two temperature channels, e.g. [\"T1\", \"T2\"]");
  for (size_t i = 0; i < 2; ++i) {
    const json& ch = pair[i];
    // A temperature channel of the tidy CSV: T<digit>... or T_<name>.
    if (!ch.is_string() || ch.get<std::string>().size() < 2 || ch.get<std::string>()[0] != 'T') {
      r.Fail("pair", fmt::format("expected two temperature channels, e.g. [\"T1\", \"T2\"], found {}", pair.dump()));
    }
    c.pair[i] = ch.get<std::string>();
  }
  if (c.pair[0] == c.pair[1]) r.Fail("pair", fmt::format("expected two different channels, found {}", pair.dump()));

  // A B0 window longer than the time limit can never be filled.
  c.b0_window_s = r.Number("B0_window_s", 0.0, kMaxAbsTime_s);
  if (!(c.b0_window_s > 0.0)) r.Fail("B0_window_s", "must be positive");

  // Each term A_kl f_k Ti0^l alone stays within the bias limit for any temperatures the data can
  // hold (|Ti0| <= 150 °C, |dT| and |Tj - Ti| <= the span): with the bias itself bounded, every
  // compensated value is then finite and within what the tidy CSV holds.
  const double t_max = std::max(-kMinTemperature_C, kMaxTemperature_C);
  const double f_max[3] = {kTemperatureSpan_C, kTemperatureSpan_C * kTemperatureSpan_C, kTemperatureSpan_C};
  const std::string shape = "a 3x3 array [[A10,A11,A12],[A20,A21,A22],[A30,A31,A32]]";
  auto matrix = [&](const std::string& key, bool signed_values, Eigen::Matrix3d& out) {
    const json& A = r.Array(key, 3, shape);
    for (int k = 0; k < 3; ++k) {
      if (!A[k].is_array() || A[k].size() != 3) r.Fail(key, fmt::format("expected {}, found row {}", shape, A[k].dump()));
      for (int l = 0; l < 3; ++l) {
        const double limit = kMaxAbsBias_dph / (f_max[k] * std::pow(t_max, l));
        out(k, l) = r.Number(key, A[k][l], fmt::format("{}[{}][{}]", key, k, l), signed_values ? -limit : 0.0, limit,
                             fmt::format(": its term of Eq. (2) alone would exceed the bias limit of ±{:g} °/h for "
                                         "temperatures within {:g}...{:g} °C", kMaxAbsBias_dph, kMinTemperature_C,
                                         kMaxTemperature_C));
      }
    }
  };
  matrix("A", true, c.A);
  if (j.contains("A_stderr")) matrix("A_stderr", false, c.A_stderr);  // optional: fit writes it for information

  const json& range = r.Array("T10_range_C", 2, "[min, max] in °C");
  for (size_t i = 0; i < 2; ++i) {
    c.t10_range_C[i] = r.Number("T10_range_C", range[i], fmt::format("T10_range_C[{}]", i), kMinTemperature_C,
                                kMaxTemperature_C);
  }
  if (c.t10_range_C[0] > c.t10_range_C[1]) r.Fail("T10_range_C", fmt::format("expected [min, max], found {}", range.dump()));

  const double huge = std::numeric_limits<double>::max();  // informative numbers: finite, >= 0
  if (j.contains("condition_number")) c.condition_number = r.Number("condition_number", 0.0, huge);
  if (j.contains("residual_rms_dph")) c.residual_rms_dph = r.Number("residual_rms_dph", 0.0, huge);
  if (j.contains("method")) {
    c.method = r.String("method");
    if (c.method != "joint" && c.method != "two_stage") {
      r.Fail("method", fmt::format("expected \"joint\" or \"two_stage\", found \"{}\"", c.method));
    }
  }
  if (j.contains("runs")) {
    const json& runs = j["runs"];
    if (!runs.is_array() || !std::all_of(runs.begin(), runs.end(), [](const json& e) { return e.is_string(); })) {
      r.Fail("runs", fmt::format("expected an array of run ids, found {}", runs.dump()));
    }
    for (const auto& id : runs) c.runs.push_back(id.get<std::string>());
  }
  return c;
}

}  // namespace

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
  return FromJson(j, source, {});
}

Guo2006Coefficients ParseCoefficients(std::string_view text, const std::string& source) {
  // nlohmann skips a UTF-8 byte-order mark itself.
  const json j = json::parse(text, nullptr, /*allow_exceptions=*/false);
  if (j.is_discarded()) {
    ErrorPosition error;
    json::sax_parse(text, &error);
    const auto before = text.substr(0, std::min(error.byte, text.size()));
    const auto line = 1 + std::count(before.begin(), before.end(), '\n');
    const auto column = before.size() - (before.rfind('\n') == std::string_view::npos ? 0 : before.rfind('\n') + 1);
    throw InputError(fmt::format("{}:{}:{}: not valid JSON: {} (expected a coefficients file as 'rlgtherm fit -o' writes "
                                 "it; numbers must be finite doubles)", source, line, column, Reason(error.message)));
  }
  return FromJson(j, source, text);
}

Guo2006Coefficients ReadCoefficientsFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!std::filesystem::is_regular_file(path) || !in) throw InputError(fmt::format("{}: cannot open coefficient file", path));
  std::ostringstream text;
  text << in.rdbuf();
  return ParseCoefficients(text.str(), path);
}

}  // namespace rlg::model
