#include "validation/baseline.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <fmt/format.h>
#include <fstream>
#include <sstream>

#include "sim/errors.h"

namespace rlg::validation {
namespace {

using nlohmann::json;

/// A finite number at `key`, or nullopt (absent, null: an infinity written as null).
std::optional<double> Number(const json& j, const char* key) {
  const auto it = j.find(key);
  if (it == j.end() || !it->is_number()) return std::nullopt;
  const double v = it->get<double>();
  return std::isfinite(v) ? std::optional<double>(v) : std::nullopt;
}

std::string Label(const std::string& metric, const std::string& run, const std::string& compensator) {
  std::string s = run.empty() ? metric : fmt::format("{} {}", metric, run);
  return compensator.empty() ? s : fmt::format("{} [{}]", s, compensator);
}

/// One metric of a one-gyro suite: regressed when new - old > k sqrt(s_old² + s_new²).
BaselineComparison Compare(const std::string& metric, const std::string& run, const std::string& compensator,
                           double old_value, double new_value, double old_sigma, double new_sigma, double k,
                           const std::string& unit, const std::string& noise) {
  BaselineComparison c;
  c.metric = metric;
  c.run = run;
  c.compensator = compensator;
  c.old_value = old_value;
  c.new_value = new_value;
  c.unit = unit;
  const double sigma = std::hypot(old_sigma, new_sigma);
  c.limit = old_value + k * sigma;
  c.regressed = new_value > c.limit;
  const double change = new_value - old_value;
  c.detail = fmt::format("{:.4g} -> {:.4g} {}, {:+.3g}{}, {} the noise of the difference (1 sigma {:.3g} {}: {}) times "
                         "{:g}: limit {:.4g}",
                         old_value, new_value, unit, change,
                         old_value != 0.0 ? fmt::format(" ({:+.0f} %)", 100.0 * change / std::abs(old_value)) : "",
                         c.regressed ? "beyond" : "within", sigma, unit, noise, k, c.limit);
  if (sigma > 0.0) c.detail += fmt::format(" ({:+.1f} sigma)", change / sigma);
  return c;
}

void CompareSuites(const json& current, const json& baseline, double k, BaselineReport& out) {
  auto key = [](const json& row) {
    return std::make_pair(row.value("run", std::string()), row.value("compensator", std::string()));
  };
  const json& old_rows = baseline.at("table2");
  std::vector<bool> matched(old_rows.size(), false);
  // Each baseline row by its key, found in O(log n) per current row (the first of equal keys).
  std::map<std::pair<std::string, std::string>, size_t> old_index;
  for (size_t o = 0; o < old_rows.size(); ++o) old_index.emplace(key(old_rows[o]), o);
  for (const json& row : current.at("table2")) {
    // Named, not a structured binding: the lambdas below capture them (C++17 and clang 14).
    const std::pair<std::string, std::string> row_key = key(row);
    const std::string& run = row_key.first;
    const std::string& compensator = row_key.second;
    const auto found = old_index.find(row_key);
    const size_t o = found == old_index.end() ? old_rows.size() : found->second;
    if (o == old_rows.size()) {
      out.notes.push_back(fmt::format("{}: not in the baseline (compared from the next baseline on)",
                                      Label("run", run, compensator)));
      continue;
    }
    matched[o] = true;
    const json& old = old_rows[o];
    auto missing = [&](const char* what) {
      out.notes.push_back(fmt::format("{}: {} not compared: the baseline or this report lacks it",
                                      Label(what, run, compensator), what));
    };
    // |bias after| against the B0 window mean's error.
    const auto ob = Number(old, "bias_after_dph"), nb = Number(row, "bias_after_dph");
    const auto oe = Number(old, "b0_error_dph"), ne = Number(row, "b0_error_dph");
    if (ob && nb && oe && ne) {
      out.compared.push_back(Compare("abs_bias_after_dph", run, compensator, std::abs(*ob), std::abs(*nb), *oe, *ne, k,
                                     "°/h", "the B0 window mean's error"));
    } else {
      missing("abs_bias_after_dph");
    }
    // Stabilities against the sampling error of a standard deviation of n block means.
    for (const auto& [metric, blocks] : {std::pair<const char*, const char*>{"stability_after_dph", "stability_blocks"},
                                         {"stability_100s_after_dph", "stability_100s_blocks"}}) {
      const auto os = Number(old, metric), ns = Number(row, metric);
      const auto on = Number(old, blocks), nn = Number(row, blocks);
      if (os && ns && on && nn && *on > 1 && *nn > 1) {
        out.compared.push_back(Compare(metric, run, compensator, *os, *ns, *os / std::sqrt(2.0 * (*on - 1.0)),
                                       *ns / std::sqrt(2.0 * (*nn - 1.0)), k, "°/h",
                                       fmt::format("s / sqrt(2 (n - 1)) of {:.0f} and {:.0f} blocks", *on, *nn)));
      } else {
        missing(metric);
      }
    }
    // The peak: one 100 s mean's error and the B0 window's.
    const auto op = Number(old, "peak_abs_100s_after_dph"), np = Number(row, "peak_abs_100s_after_dph");
    const auto o1 = Number(old, "error_100s_dph"), n1 = Number(row, "error_100s_dph");
    if (op && np && o1 && n1 && oe && ne) {
      out.compared.push_back(Compare("peak_abs_100s_after_dph", run, compensator, *op, *np, std::hypot(*oe, *o1),
                                     std::hypot(*ne, *n1), k, "°/h", "a 100 s mean's error and the B0 window's"));
    } else {
      missing("peak_abs_100s_after_dph");
    }
    // |trend| against its standard error (none without a temperature change).
    const auto ot = Number(old, "trend_dph_per_C"), nt = Number(row, "trend_dph_per_C");
    const auto ote = Number(old, "trend_stderr_dph_per_C"), nte = Number(row, "trend_stderr_dph_per_C");
    if (ot && nt && ote && nte) {
      out.compared.push_back(Compare("abs_trend_dph_per_C", run, compensator, std::abs(*ot), std::abs(*nt), *ote, *nte,
                                     k, "°/h/°C", "the trend's standard error"));
    }
  }
  for (size_t o = 0; o < old_rows.size(); ++o) {
    if (matched[o]) continue;
    const auto [run, compensator] = key(old_rows[o]);
    BaselineComparison c;
    c.metric = "compensated";
    c.run = run;
    c.compensator = compensator;
    c.regressed = true;
    c.detail = "compensated and checked in the baseline, not any more: a gate must not lose runs silently (make a "
               "new baseline if this is meant)";
    out.compared.push_back(std::move(c));
  }
}

/// [lo, hi] of a population metric's interval (nullopt for an unbounded side).
std::pair<std::optional<double>, std::optional<double>> Interval(const json& m, const char* key) {
  const auto it = m.find(key);
  if (it == m.end() || !it->is_array() || it->size() != 2) return {std::nullopt, std::nullopt};
  auto side = [](const json& v) { return v.is_number() ? std::optional<double>(v.get<double>()) : std::nullopt; };
  return {side((*it)[0]), side((*it)[1])};
}

void ComparePopulations(const json& current, const json& baseline, double k, BaselineReport& out) {
  const json& now = current.at("population");
  const json& old = baseline.at("population");
  for (const json& m : now.at("metrics")) {
    const std::string metric = m.value("metric", std::string());
    if (metric.find("_after_") == std::string::npos) continue;  // "before" is the gyro, not the compensation
    const std::string run = m.value("run", std::string()), compensator = m.value("compensator", std::string());
    const auto& old_metrics = old.at("metrics");
    const auto o = std::find_if(old_metrics.begin(), old_metrics.end(), [&](const json& x) {
      return x.value("metric", std::string()) == metric && x.value("run", std::string()) == run &&
             x.value("compensator", std::string()) == compensator;
    });
    if (o == old_metrics.end()) {
      out.notes.push_back(fmt::format("{}: not in the baseline", Label(metric, run, compensator)));
      continue;
    }
    for (const auto& [quantile, interval] :
         {std::pair<const char*, const char*>{"median", "median_interval"}, {"p95", "p95_interval"}}) {
      const auto [old_lo, old_hi] = Interval(*o, interval);
      const auto [new_lo, new_hi] = Interval(m, interval);
      const std::string name = fmt::format("{} {}", quantile, metric);
      if (!old_hi || !new_lo) {
        out.notes.push_back(fmt::format("{}: not compared: its 95 % interval is unbounded for this many gyros",
                                        Label(name, run, compensator)));
        continue;
      }
      BaselineComparison c;
      c.metric = name;
      c.run = run;
      c.compensator = compensator;
      c.old_value = o->value(quantile, 0.0);
      c.new_value = m.value(quantile, 0.0);
      c.limit = *old_hi;
      c.unit = "°/h";
      c.regressed = *new_lo > *old_hi;
      c.detail = fmt::format("{:.4g} -> {:.4g} °/h; 95 % intervals [{:.4g}, {}] -> [{:.4g}, {}]: {}", c.old_value,
                             c.new_value, old_lo.value_or(NAN), fmt::format("{:.4g}", *old_hi), *new_lo,
                             new_hi ? fmt::format("{:.4g}", *new_hi) : "unbounded",
                             c.regressed ? "the new one lies wholly above the old one" : "they overlap");
      out.compared.push_back(std::move(c));
    }
  }
  const auto ny = now.find("yield"), oy = old.find("yield");
  if (ny == now.end() || oy == old.end()) {
    out.notes.push_back("yield: not compared: the baseline or this report lacks it");
    return;
  }
  const double n_new = ny->value("gyros", 0.0), n_old = oy->value("gyros", 0.0);
  const double p_new = ny->value("passing_gyros", 0.0), p_old = oy->value("passing_gyros", 0.0);
  if (n_new < 1 || n_old < 1) return;
  const double y_new = p_new / n_new, y_old = p_old / n_old, pooled = (p_new + p_old) / (n_new + n_old);
  const double se = std::sqrt(pooled * (1.0 - pooled) * (1.0 / n_old + 1.0 / n_new));
  BaselineComparison c;
  c.metric = "yield";
  c.compensator = "population";
  c.old_value = y_old;
  c.new_value = y_new;
  c.limit = y_old - k * se;
  c.unit = "";
  c.regressed = y_new < c.limit;
  c.detail = fmt::format("{:.0f} of {:.0f} -> {:.0f} of {:.0f} gyros pass every check ({:.1f} % -> {:.1f} %), {} {:g} "
                         "pooled binomial standard errors ({:.2g}) of the old yield: limit {:.1f} %",
                         p_old, n_old, p_new, n_new, 100.0 * y_old, 100.0 * y_new, c.regressed ? "below" : "within", k,
                         se, 100.0 * c.limit);
  out.compared.push_back(std::move(c));
}

}  // namespace

bool BaselineReport::passed() const { return regressions() == 0; }

size_t BaselineReport::regressions() const {
  return static_cast<size_t>(
      std::count_if(compared.begin(), compared.end(), [](const BaselineComparison& c) { return c.regressed; }));
}

json ReadBaseline(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw InputError(fmt::format("{}: --baseline: cannot read the file (expected a previous validate --json)", path));
  std::stringstream text;
  text << in.rdbuf();
  json j;
  try {
    j = json::parse(text.str());
  } catch (const json::parse_error& e) {
    throw InputError(fmt::format("{}: --baseline: not JSON ({}); expected what validate --json printed", path, e.what()));
  }
  if (!j.is_object() || !(j.contains("table2") || j.contains("population"))) {
    throw InputError(fmt::format("{}: --baseline: not a validate --json report (it has neither \"table2\" nor "
                                 "\"population\")",
                                 path));
  }
  return j;
}

BaselineReport CompareWithBaseline(const json& current, const json& baseline, const std::string& file,
                                   double max_sigma) {
  BaselineReport out;
  out.file = file;
  out.max_sigma = max_sigma;
  const bool population = current.contains("population");
  if (population != baseline.contains("population")) {
    throw InputError(fmt::format("{}: --baseline: a report of a {} suite, this suite is {}: compare like with like",
                                 file, baseline.contains("population") ? "population" : "one-gyro",
                                 population ? "a population suite" : "a one-gyro suite"));
  }
  try {
    if (population) {
      ComparePopulations(current, baseline, max_sigma, out);
    } else {
      CompareSuites(current, baseline, max_sigma, out);
    }
  } catch (const json::exception& e) {
    throw InputError(fmt::format("{}: --baseline: not a validate --json report of this kind ({})", file, e.what()));
  }
  return out;
}

json BaselineJson(const BaselineReport& r) {
  json j = {{"file", r.file}, {"max_sigma", r.max_sigma}, {"compared", json::array()}};
  for (const auto& c : r.compared) {
    j["compared"].push_back({{"metric", c.metric},
                             {"run", c.run},
                             {"compensator", c.compensator},
                             {"old", c.old_value},
                             {"new", c.new_value},
                             {"limit", c.limit},
                             {"unit", c.unit},
                             {"regressed", c.regressed},
                             {"detail", c.detail}});
  }
  j["regressed"] = r.regressions();
  j["notes"] = r.notes;
  j["passed"] = r.passed();
  return j;
}

std::vector<Check> BaselineChecks(const BaselineReport& r) {
  std::vector<Check> out;
  for (const auto& c : r.compared) {
    Check ch;
    ch.name = "baseline " + c.metric;
    ch.run = c.run;
    ch.compensator = c.compensator;
    ch.passed = !c.regressed;
    if (c.metric != "compensated") {
      ch.value = c.new_value;
      ch.limit = c.limit;
      ch.unit = c.unit;
    }
    ch.detail = fmt::format("against {}: {}", r.file, c.detail);
    out.push_back(std::move(ch));
  }
  return out;
}

std::string BaselineText(const BaselineReport& r) {
  std::string out = fmt::format("\nBaseline {}: {} metrics compared, each with the noise of its two measurements "
                                "(beyond {:g} sigma, or intervals apart: regressed), {} regressed\n",
                                r.file, r.compared.size(), r.max_sigma, r.regressions());
  for (const auto& c : r.compared) {
    if (c.regressed) out += fmt::format("  REGRESSED {}: {}\n", Label(c.metric, c.run, c.compensator), c.detail);
  }
  for (const auto& n : r.notes) out += fmt::format("  note: {}\n", n);
  out += fmt::format("baseline: {}\n", r.passed() ? "no regression" : "REGRESSED");
  return out;
}

}  // namespace rlg::validation
