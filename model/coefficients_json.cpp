#include "model/coefficients_json.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fmt/format.h>
#include <fmt/ranges.h>
#include <fstream>
#include <limits>
#include <set>
#include <sstream>

#include "io/input_file.h"
#include "model/linear_fit.h"
#include "sim/errors.h"
#include "sim/limits.h"
#include "sim/spelling.h"

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

/// Line of the `nth` (0-based) `"subkey":` after the first `"key":` in `text`, 0 if there is
/// none: the line of an element's key inside an array of objects (coefficients[2].value).
int NestedKeyLine(std::string_view text, const std::string& key, const std::string& subkey, size_t nth) {
  const int key_line = KeyLine(text, key);
  if (key_line == 0) return 0;
  size_t from = 0;
  for (int line = 1; line < key_line; ++line) from = text.find('\n', from) + 1;
  const std::string quoted = "\"" + subkey + "\"";
  size_t count = 0;
  for (size_t at = text.find(quoted, from); at != std::string_view::npos; at = text.find(quoted, at + 1)) {
    size_t next = at + quoted.size();
    while (next < text.size() && std::isspace(static_cast<unsigned char>(text[next]))) ++next;
    if (next >= text.size() || text[next] != ':') continue;
    if (count++ == nth) return 1 + static_cast<int>(std::count(text.begin(), text.begin() + static_cast<std::ptrdiff_t>(at), '\n'));
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
  /// The same for a key inside element `nth` of the array at `key` (the line of its `subkey`).
  [[noreturn]] void FailNested(const std::string& key, const std::string& subkey, size_t nth, const std::string& what) const {
    int line = NestedKeyLine(text_, key, subkey, nth);
    if (line == 0) line = KeyLine(text_, key);
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
  /// Refuses a key of `object` that is none of `keys` (`inside`: "" at the top, else e.g.
  /// "terms[1]"): one that misspells a key of `keys` first, naming that key, else the first,
  /// listing `keys`. A key a file does not know is no key it may ignore: "modell" would leave
  /// the file read as Eq. (2).
  void RefuseUnknownKeys(const json& object, const std::vector<std::string>& keys, const std::string& inside) const {
    if (!object.is_object()) return;
    std::string unknown, nearest;
    for (const auto& [key, value] : object.items()) {
      if (std::find(keys.begin(), keys.end(), key) != keys.end()) continue;
      const std::string n = sim::NearestName(key, keys);
      if (unknown.empty() || (nearest.empty() && !n.empty())) unknown = key, nearest = n;
    }
    if (unknown.empty()) return;
    const int line = KeyLine(text_, unknown);
    throw InputError(fmt::format("{}: unknown key '{}'{}; {} (a coefficients file as 'rlgtherm fit -o' writes it)",
                                 line > 0 ? fmt::format("{}:{}", source_, line) : source_, unknown,
                                 inside.empty() ? "" : " in " + inside,
                                 nearest.empty() ? fmt::format("expected {}", fmt::join(keys, ", "))
                                                 : fmt::format("did you mean '{}'?", nearest)));
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
  // What ToJson writes, and nothing else.
  r.RefuseUnknownKeys(j, {"model", "pair", "B0_window_s", "A", "A_stderr", "A_stderr_dof", "A_ci95_halfwidth", "stderr_method",
                          "T10_range_C", "condition_number", "residual_rms_dph", "method", "runs"}, "");
  Guo2006Coefficients c;
  // A file without "model" is Eq. (2): the family's first member.
  if (j.contains("model") && r.String("model") != "guo2006") {
    r.Fail("model", fmt::format("expected \"guo2006\", found {}", j["model"].dump()));
  }

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
    const std::string method = r.String("method");
    const std::optional<Guo2006Method> parsed = ParseGuo2006Method(method);
    if (!parsed) r.Fail("method", fmt::format("expected \"joint\" or \"two_stage\", found \"{}\"", method));
    c.method = *parsed;
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

/// A temperature channel name of the tidy CSV: T<digit>... or T_<name>.
bool IsChannel(const json& v) {
  return v.is_string() && v.get<std::string>().size() >= 2 && v.get<std::string>()[0] == 'T';
}

/// The largest |coefficient| whose term alone stays within the bias limit for temperatures
/// within the data's limits (|d|, |T - play|, |T_L - T|, |Tj - T| <= the span) and rates up to
/// 100 °C/min; the constant at the bias limit itself.
double CoefficientLimit(const std::string& name) {
  using namespace sim::limits;
  if (name == "c0") return kMaxAbsBias_dph;
  if (name.size() == 2 && name[0] == 'c') return kMaxAbsBias_dph / std::pow(kTemperatureSpan_C, name[1] - '0');
  if (name == "rate") return kMaxBiasPerRate;
  return kMaxBiasPerC;
}

/// The model's channel, order, offset rule, reference and range (°C), B0 window (s) and what it
/// does beyond its range, from the top level of a coefficients file.
void ReadPolyHeader(const Reader& r, const json& j, PolySpec& s) {
  using namespace sim::limits;
  if (!IsChannel(r.Get("channel"))) {
    r.Fail("channel", fmt::format("expected a temperature channel such as \"T1\", found {}", j["channel"].dump()));
  }
  s.channel = j["channel"].get<std::string>();
  const json& order = r.Get("order");
  if (!order.is_number_integer() || order.get<long long>() < 1 || order.get<long long>() > 5) {
    r.Fail("order", fmt::format("expected an integer 1 to 5, found {}", order.dump()));
  }
  s.order = static_cast<int>(order.get<long long>());
  const std::string offset = r.String("offset");
  if (offset != "fitted" && offset != "power_on") {
    r.Fail("offset", fmt::format("expected \"fitted\" or \"power_on\", found \"{}\"", offset));
  }
  s.offset = offset == "fitted" ? OffsetRule::kFitted : OffsetRule::kPowerOn;
  s.reference_C = r.Number("reference_C", kMinTemperature_C, kMaxTemperature_C);
  const json& range = r.Array("range_C", 2, "[min, max] in °C");
  for (size_t i = 0; i < 2; ++i) {
    s.range_C[i] = r.Number("range_C", range[i], fmt::format("range_C[{}]", i), kMinTemperature_C, kMaxTemperature_C);
  }
  if (s.range_C[0] > s.range_C[1]) r.Fail("range_C", fmt::format("expected [min, max], found {}", range.dump()));
  if (s.offset == OffsetRule::kPowerOn || j.contains("B0_window_s")) {
    s.b0_window_s = r.Number("B0_window_s", 0.0, kMaxAbsTime_s);
    if (!(s.b0_window_s > 0.0)) r.Fail("B0_window_s", "must be positive");
  }

  if (j.contains("beyond_range")) {
    const std::string beyond = r.String("beyond_range");
    if (beyond != "hold" && beyond != "extrapolate") {
      r.Fail("beyond_range", fmt::format("expected \"hold\" or \"extrapolate\", found \"{}\"", beyond));
    }
    s.extrapolate = beyond == "extrapolate";
  }
}

/// Refuses element i of "terms" with `what`, naming the line of its "term".
[[noreturn]] void FailTerm(const Reader& r, size_t i, const std::string& what) {
  r.FailNested("terms", "term", i, fmt::format("terms[{}]: {}", i, what));
}

/// The number at `key` of term e (terms[i]), within lo...hi (lo itself excluded if open_lo).
double TermNumber(const Reader& r, const json& e, size_t i, const std::string& key, double lo, double hi, bool open_lo) {
  auto fail = [&](const std::string& what) { FailTerm(r, i, what); };
  if (!e.contains(key) || !e[key].is_number()) fail(fmt::format("'{}' must be a number, found {}", key, e.contains(key) ? e[key].dump() : "nothing"));
  const double x = e[key].get<double>();
  if (!(open_lo ? x > lo : x >= lo) || !(x <= hi)) fail(fmt::format("{} = {:g} is outside {:g}...{:g}", key, x, lo, hi));
  return x;
}

/// One factor fe of the product term terms[i]: its channel, the one it is minus, whether it
/// is a rate, and its range (°C, or °C/min for a rate).
Factor ReadFactor(const Reader& r, size_t i, const json& fe) {
  using namespace sim::limits;
  auto fail = [&](const std::string& what) { FailTerm(r, i, what); };
  Factor f;
  auto bad = [&](const std::string& why) { fail(fmt::format("factor {}: {}", fe.dump(), why)); };
  if (!fe.is_object()) bad("expected an object");
  r.RefuseUnknownKeys(fe, {"channel", "minus", "rate", "range"}, fmt::format("terms[{}].factors", i));
  if (!fe.contains("channel") || !IsChannel(fe["channel"])) bad("\"channel\" must be a temperature channel");
  f.channel = fe["channel"].get<std::string>();
  if (fe.contains("minus")) {
    if (!IsChannel(fe["minus"]) || fe["minus"] == fe["channel"]) bad("\"minus\" must be another temperature channel");
    f.minus = fe["minus"].get<std::string>();
  }
  if (fe.contains("rate")) {
    if (!fe["rate"].is_boolean()) bad("\"rate\" must be true or false");
    f.rate = fe["rate"].get<bool>();
  }
  const json* range = fe.contains("range") ? &fe["range"] : nullptr;
  if (!range || !range->is_array() || range->size() != 2 || !(*range)[0].is_number() || !(*range)[1].is_number()) {
    bad("\"range\" must be [min, max] (°C, or °C/min for a rate)");
  }
  f.range = {(*range)[0].get<double>(), (*range)[1].get<double>()};
  const double limit = f.rate ? 1e4 : kTemperatureSpan_C;
  if (!(f.range[0] <= f.range[1]) || !(std::abs(f.range[0]) <= limit) || !(std::abs(f.range[1]) <= limit)) {
    bad(fmt::format("\"range\" must be [min, max] within ±{:g}", limit));
  }
  return f;
}

/// The factors (and the time constant, s, if one is a rate) of the product term e (terms[i]).
void ReadProduct(const Reader& r, const json& e, size_t i, const PolySpec& s, PolyTerm& t) {
  using namespace sim::limits;
  auto fail = [&](const std::string& what) { FailTerm(r, i, what); };
  const json* factors = e.contains("factors") ? &e["factors"] : nullptr;
  if (!factors || !factors->is_array() || factors->empty() || factors->size() > 4) {
    fail(fmt::format("a product needs \"factors\": 1 to 4 of {{\"channel\", \"minus\", \"rate\", \"range\"}}, found {}",
                     e.dump()));
  }
  for (const json& fe : *factors) t.factors.push_back(ReadFactor(r, i, fe));
  if (!std::is_sorted(t.factors.begin(), t.factors.end())) {
    fail("the factors must be in canonical order (values before rates, channels before differences, then by name)");
  }
  std::string why;
  const auto parsed = ParseTerm(t.Name(), s.channel, &why);
  if (!parsed || parsed->kind != TermKind::kProduct) {
    fail(fmt::format("{} is not a product term{}", t.Name(), why.empty() ? " (it is one of the named terms)" : ": " + why));
  }
  if (e.contains("name") && e["name"] != t.Name()) {
    fail(fmt::format("\"name\" {} does not match its factors ({})", e["name"].dump(), t.Name()));
  }
  if (t.HasRate()) t.tau_s = TermNumber(r, e, i, "tau_s", kMinLag, kMaxLag, false);
}

/// Term e, element i of "terms": its kind and its parameters.
PolyTerm ReadTerm(const Reader& r, const json& e, size_t i, const PolySpec& s) {
  using namespace sim::limits;
  auto fail = [&](const std::string& what) { FailTerm(r, i, what); };
  if (!e.is_object() || !e.contains("term") || !e["term"].is_string() || !TermKindOf(e["term"].get<std::string>())) {
    fail(fmt::format("expected {{\"term\": \"rate\"|\"hysteresis\"|\"lag\"|\"gradient\", ...}}, found {}", e.dump()));
  }
  r.RefuseUnknownKeys(e, {"term", "tau_s", "width_C", "channel", "name", "factors"}, fmt::format("terms[{}]", i));
  PolyTerm t;
  t.kind = *TermKindOf(e["term"].get<std::string>());
  switch (t.kind) {
    case TermKind::kRate:
    case TermKind::kLag: t.tau_s = TermNumber(r, e, i, "tau_s", kMinLag, kMaxLag, false); break;
    case TermKind::kHysteresis: t.width_C = TermNumber(r, e, i, "width_C", 0.0, kTemperatureSpan_C, true); break;
    case TermKind::kGradient:
      if (!e.contains("channel") || !IsChannel(e["channel"])) {
        fail(fmt::format("a gradient needs \"channel\": another temperature channel, found {}", e.dump()));
      }
      t.channel = e["channel"].get<std::string>();
      if (t.channel == s.channel) fail(fmt::format("a gradient to the model's own channel {}", s.channel));
      break;
    case TermKind::kProduct: ReadProduct(r, e, i, s, t); break;
  }
  return t;
}

/// Coefficient e, element i of "coefficients", which must be the regressor `name` (in `unit`):
/// its value within the bias limit, and its standard error and degrees of freedom if given.
Coefficient ReadCoefficient(const Reader& r, const json& e, size_t i, const std::string& name, const std::string& unit,
                            const PolySpec& s) {
  using namespace sim::limits;
  auto fail = [&](const std::string& what) { r.FailNested("coefficients", "name", i, fmt::format("coefficients[{}]: {}", i, what)); };
  r.RefuseUnknownKeys(e, {"name", "unit", "value", "stderr", "dof", "ci95_halfwidth"}, fmt::format("coefficients[{}]", i));
  if (!e.is_object() || !e.contains("name") || e["name"] != name) {
    fail(fmt::format("expected {{\"name\": \"{}\", \"value\": ...}} (the order of the regressors), found {}", name, e.dump()));
  }
  Coefficient c;
  c.name = name;
  c.unit = unit;
  double limit = CoefficientLimit(c.name);
  for (const auto& t : s.terms) {
    if (t.kind != TermKind::kProduct || t.Name() != c.name) continue;
    limit = kMaxAbsBias_dph;
    for (const auto& f : t.factors) limit /= f.rate ? 100.0 : kTemperatureSpan_C;
  }
  if (!e.contains("value") || !e["value"].is_number()) fail(fmt::format("'{}': value must be a number", c.name));
  c.value = e["value"].get<double>();
  if (!(std::abs(c.value) <= limit)) {
    fail(fmt::format("'{}' = {:g} is outside {:g}...{:g}: its term alone would exceed the bias limit of ±{:g} °/h for "
                     "temperatures within {:g}...{:g} °C{}",
                     c.name, c.value, -limit, limit, kMaxAbsBias_dph, kMinTemperature_C, kMaxTemperature_C,
                     c.name == "rate" ? " and rates up to 100 °C/min" : ""));
  }
  for (const char* key : {"stderr", "dof"}) {
    if (!e.contains(key)) continue;
    if (!e[key].is_number() || !(e[key].get<double>() >= 0.0) || !std::isfinite(e[key].get<double>())) {
      fail(fmt::format("'{}': {} must be a finite number >= 0, found {}", c.name, key, e[key].dump()));
    }
    (std::string(key) == "stderr" ? c.standard_error : c.dof) = e[key].get<double>();
  }
  // A Student's t of fewer than one degree of freedom is no interval a fit reports (0: none).
  if (c.dof != 0.0 && !(c.dof >= 1.0 && c.dof <= 1e9)) {
    fail(fmt::format("'{}': dof = {:g}: expected 0 (none) or 1...1e9", c.name, c.dof));
  }
  return c;
}

/// The record of an automatic selection, the file's "selection": the rule, the folds and each
/// step's candidate, cross-validated RMS (°/h) and verdict.
SelectionRecord ReadSelection(const Reader& r, const json& sel) {
  r.RefuseUnknownKeys(sel, {"rule", "folds", "steps"}, "selection");
  if (sel.contains("steps") && sel["steps"].is_array()) {
    for (size_t i = 0; i < sel["steps"].size(); ++i) {
      r.RefuseUnknownKeys(sel["steps"][i], {"candidate", "cv_rms_dph", "accepted", "note", "parameters"},
                          fmt::format("selection.steps[{}]", i));
    }
  }
  const bool ok = sel.is_object() && sel.contains("steps") && sel["steps"].is_array() &&
                  std::all_of(sel["steps"].begin(), sel["steps"].end(), [](const json& e) {
                    return e.is_object() && e.contains("candidate") && e["candidate"].is_string() &&
                           e.contains("accepted") && e["accepted"].is_boolean() && e.contains("cv_rms_dph") &&
                           (e["cv_rms_dph"].is_number() || e["cv_rms_dph"].is_null());
                  });
  if (!ok) r.Fail("selection", "expected {\"rule\": ..., \"folds\": n, \"steps\": [{\"candidate\", \"cv_rms_dph\", \"accepted\"}, ..]}");
  SelectionRecord rec;
  if (sel.contains("rule") && sel["rule"].is_string()) rec.rule = sel["rule"].get<std::string>();
  if (sel.contains("folds") && sel["folds"].is_number_integer()) rec.folds = sel["folds"].get<int>();
  for (const auto& e : sel["steps"]) {
    SelectionStep step;
    step.candidate = e["candidate"].get<std::string>();
    step.cv_rms_dph = e["cv_rms_dph"].is_null() ? std::numeric_limits<double>::infinity() : e["cv_rms_dph"].get<double>();
    step.accepted = e["accepted"].get<bool>();
    if (e.contains("note") && e["note"].is_string()) step.note = e["note"].get<std::string>();
    if (e.contains("parameters") && e["parameters"].is_number_integer()) step.parameters = e["parameters"].get<int>();
    rec.steps.push_back(step);
  }
  return rec;
}

PolyModel PolyFromJson(const json& j, const std::string& source, std::string_view text) {
  const Reader r(j, source, text);
  // What ToJson writes, and nothing else, here and in each term, factor, coefficient and step.
  r.RefuseUnknownKeys(j, {"model", "preset", "channel", "order", "offset", "reference_C", "range_C", "B0_window_s",
                          "beyond_range", "terms", "coefficients", "stderr_method", "clusters", "condition_number",
                          "residual_rms_dph", "runs", "selection"}, "");
  PolyModel m;
  PolySpec& s = m.spec;
  ReadPolyHeader(r, j, s);
  const json& terms = r.Get("terms");
  if (!terms.is_array()) r.Fail("terms", fmt::format("expected an array of terms, found {}", terms.dump()));
  std::set<std::string> names;
  for (size_t i = 0; i < terms.size(); ++i) {
    const PolyTerm t = ReadTerm(r, terms[i], i, s);
    if (!names.insert(t.Name()).second) FailTerm(r, i, fmt::format("'{}' is named twice", t.Name()));
    s.terms.push_back(t);
  }

  const std::vector<std::string> expected = s.CoefficientNames();
  const std::vector<std::string> units = s.CoefficientUnits();
  const json& coefficients = r.Get("coefficients");
  if (!coefficients.is_array() || coefficients.size() != expected.size()) {
    r.Fail("coefficients", fmt::format("expected {} coefficients ({}), found {}", expected.size(), fmt::join(expected, ", "),
                                       coefficients.is_array() ? std::to_string(coefficients.size()) : coefficients.dump()));
  }
  for (size_t i = 0; i < expected.size(); ++i) {
    m.coefficients.push_back(ReadCoefficient(r, coefficients[i], i, expected[i], units[i], s));
  }

  const double huge = std::numeric_limits<double>::max();  // informative numbers: finite, >= 0
  if (j.contains("condition_number")) m.condition_number = r.Number("condition_number", 0.0, huge);
  if (j.contains("residual_rms_dph")) m.residual_rms_dph = r.Number("residual_rms_dph", 0.0, huge);
  if (j.contains("preset")) {
    const std::string preset = r.String("preset");
    const std::optional<PolyPreset> parsed = ParsePolyPreset(preset);
    if (!parsed) {
      r.Fail("preset", fmt::format("expected \"poly\", \"px4\", \"ardupilot\" or \"auto\", found \"{}\"", preset));
    }
    m.preset = *parsed;
  }
  if (j.contains("stderr_method")) m.stderr_method = r.String("stderr_method");
  if (j.contains("clusters")) m.clusters = static_cast<int>(r.Number("clusters", 0.0, 1e9));
  if (j.contains("runs")) {
    const json& runs = j["runs"];
    if (!runs.is_array() || !std::all_of(runs.begin(), runs.end(), [](const json& e) { return e.is_string(); })) {
      r.Fail("runs", fmt::format("expected an array of run ids, found {}", runs.dump()));
    }
    for (const auto& id : runs) m.runs.push_back(id.get<std::string>());
  }
  if (j.contains("selection")) m.selection = ReadSelection(r, j["selection"]);
  return m;
}

/// The text of a coefficient file as JSON; syntax errors name line and column.
json ParseText(std::string_view text, const std::string& source) {
  // nlohmann skips a UTF-8 byte-order mark itself.
  json j = json::parse(text, nullptr, /*allow_exceptions=*/false);
  if (j.is_discarded()) {
    ErrorPosition error;
    json::sax_parse(text, &error);
    const auto before = text.substr(0, std::min(error.byte, text.size()));
    const auto line = 1 + std::count(before.begin(), before.end(), '\n');
    const auto column = before.size() - (before.rfind('\n') == std::string_view::npos ? 0 : before.rfind('\n') + 1);
    throw InputError(fmt::format("{}:{}:{}: not valid JSON: {} (expected a coefficients file as 'rlgtherm fit -o' writes "
                                 "it; numbers must be finite doubles)", source, line, column, Reason(error.message)));
  }
  return j;
}

std::string ReadText(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  // The system's reason: no such file, permission denied, a directory.
  std::error_code dir_ec;
  const int err = in ? (std::filesystem::is_directory(path, dir_ec) ? EISDIR : 0) : errno;
  if (err != 0 || !io::IsRegularFile(path)) {
    throw InputError(fmt::format("{}: cannot open the coefficient file: {}", path,
                                 err != 0 ? std::strerror(err) : "not a regular file"));
  }
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

FittedModel FamilyFromJson(const json& j, const std::string& source, std::string_view text) {
  if (j.is_object() && j.contains("model") && j["model"].is_string()) {
    const std::string name = j["model"].get<std::string>();
    if (name == "poly") return PolyFromJson(j, source, text);
    if (name != "guo2006") {
      Reader(j, source, text).Fail("model", fmt::format("expected \"guo2006\" or \"poly\", found \"{}\"", name));
    }
  }
  return FromJson(j, source, text);
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
                      {"method", Guo2006MethodName(c.method)},
                      {"runs", c.runs}};
  // Coefficients read back from a file carry no error model (stderr_dof 0): no intervals then.
  if (c.stderr_dof.minCoeff() > 0.0) j["A_ci95_halfwidth"] = rows(c.ConfidenceHalfWidth(0.95));
  return j;
}

Guo2006Coefficients CoefficientsFromJson(const nlohmann::json& j, const std::string& source) {
  return FromJson(j, source, {});
}

Guo2006Coefficients ParseCoefficients(std::string_view text, const std::string& source) {
  return FromJson(ParseText(text, source), source, text);
}

Guo2006Coefficients ReadCoefficientsFile(const std::string& path) { return ParseCoefficients(ReadText(path), path); }

nlohmann::json ToJson(const PolyModel& m) {
  const PolySpec& s = m.spec;
  nlohmann::json j = {{"model", "poly"},
                      {"preset", PolyPresetName(m.preset)},
                      {"channel", s.channel},
                      {"order", s.order},
                      {"offset", OffsetName(s.offset)},
                      {"reference_C", s.reference_C},
                      {"range_C", {s.range_C[0], s.range_C[1]}}};
  if (s.offset == OffsetRule::kPowerOn) j["B0_window_s"] = s.b0_window_s;
  if (s.extrapolate) j["beyond_range"] = "extrapolate";
  j["terms"] = nlohmann::json::array();
  for (const auto& t : s.terms) {
    nlohmann::json e = {{"term", TermKindName(t.kind)}};
    if (t.kind == TermKind::kRate || t.kind == TermKind::kLag) e["tau_s"] = t.tau_s;
    if (t.kind == TermKind::kHysteresis) e["width_C"] = t.width_C;
    if (t.kind == TermKind::kGradient) e["channel"] = t.channel;
    if (t.kind == TermKind::kProduct) {
      if (t.HasRate()) e["tau_s"] = t.tau_s;
      e["name"] = t.Name();
      e["factors"] = nlohmann::json::array();
      for (const auto& f : t.factors) {
        nlohmann::json fe = {{"channel", f.channel}};
        if (!f.minus.empty()) fe["minus"] = f.minus;
        if (f.rate) fe["rate"] = true;
        fe["range"] = {f.range[0], f.range[1]};
        e["factors"].push_back(fe);
      }
    }
    j["terms"].push_back(e);
  }
  j["coefficients"] = nlohmann::json::array();
  for (const auto& c : m.coefficients) {
    nlohmann::json e = {{"name", c.name}, {"unit", c.unit}, {"value", c.value}, {"stderr", c.standard_error}, {"dof", c.dof}};
    // Coefficients read back from a file without errors carry no dof: no interval then.
    if (c.dof >= 1.0) e["ci95_halfwidth"] = StudentQuantile(0.95, c.dof) * c.standard_error;
    j["coefficients"].push_back(e);
  }
  j["stderr_method"] = m.stderr_method;
  j["clusters"] = m.clusters;
  j["condition_number"] = m.condition_number;
  j["residual_rms_dph"] = m.residual_rms_dph;
  j["runs"] = m.runs;
  if (m.selection) {
    nlohmann::json steps = nlohmann::json::array();
    for (const auto& st : m.selection->steps) {
      nlohmann::json e = {{"candidate", st.candidate},
                          {"cv_rms_dph", std::isfinite(st.cv_rms_dph) ? nlohmann::json(st.cv_rms_dph) : nlohmann::json(nullptr)},
                          {"accepted", st.accepted}};
      if (!st.note.empty()) e["note"] = st.note;
      if (st.parameters > 0) e["parameters"] = st.parameters;
      steps.push_back(e);
    }
    j["selection"] = {{"rule", m.selection->rule}, {"folds", m.selection->folds}, {"steps", steps}};
  }
  return j;
}

nlohmann::json ModelToJson(const FittedModel& m) {
  return std::visit([](const auto& c) { return ToJson(c); }, m);
}

FittedModel ModelFromJson(const nlohmann::json& j, const std::string& source) { return FamilyFromJson(j, source, {}); }

FittedModel ParseModel(std::string_view text, const std::string& source) {
  return FamilyFromJson(ParseText(text, source), source, text);
}

FittedModel ReadModelFile(const std::string& path) { return ParseModel(ReadText(path), path); }

}  // namespace rlg::model
