#include "validation/suite.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <fmt/format.h>
#include <fmt/ranges.h>
#include <set>
#include <toml++/toml.h>

#include "compensation/compensator.h"
#include "io/input_file.h"
#include "io/scenario_file.h"
#include "io/toml_reader.h"
#include "compensation/model_compensator.h"
#include "validation/baseline.h"
#include "validation/fit_request_toml.h"
#include "sim/errors.h"
#include "sim/scenario.h"
#include "sim/simulator.h"

namespace rlg::validation {

using compensation::CompensateRun;
using compensation::EvaluateRun;
using compensation::EvaluationOptions;
using compensation::RunEvaluation;

std::string SuiteFit::Compensator() const { return request.model == "guo2006" ? kEq2 : request.model; }

namespace {

/// "FILE:LINE" of a TomlReader::Where ("FILE:LINE: key 'KEY' in [TABLE]").
std::string FileLine(const std::string& where) { return where.substr(0, where.find(": key '")); }

/// "FILE:LINE" of a key as written.
std::string KeyLine(const io::TomlReader& table, const std::string& key) { return FileLine(table.Where(key)); }

/// The limit keys of [checks] and of a [[checks.limits]] table (a key left out: its default).
void ReadLimits(const io::TomlReader& t, RunLimits& limits) {
  auto optional = [&](const char* key, std::optional<double>& value) {
    if (!t.Has(key)) return;
    value = t.Positive(key);
    limits.written[key] = KeyLine(t, key);
  };
  if (t.Has("bias_after_max_dph")) limits.written["bias_after_max_dph"] = KeyLine(t, "bias_after_max_dph");
  limits.bias_after_max_dph = t.Positive("bias_after_max_dph", 0.01);
  if (t.Has("bias_after_floor_sigma")) limits.written["bias_after_floor_sigma"] = KeyLine(t, "bias_after_floor_sigma");
  limits.bias_after_floor_sigma = t.Positive("bias_after_floor_sigma", 0.0, true);
  optional("stability_after_max_dph", limits.stability_after_max_dph);
  optional("stability_100s_after_max_dph", limits.stability_100s_after_max_dph);
  optional("peak_abs_100s_after_max_dph", limits.peak_abs_100s_after_max_dph);
}

}  // namespace

bool RunLimits::Selects(const std::string& run) const {
  return std::any_of(prefixes.begin(), prefixes.end(), [&](const std::string& p) { return run.rfind(p, 0) == 0; });
}

namespace {

/// A [[fits]] entry; a run compensated by two fits, or twice by one, is refused naming both.
SuiteFit ReadFit(const io::TomlReader& fit, const std::vector<SuiteFit>& earlier) {
  SuiteFit f;
  f.name = fit.String("name");
  f.request = ReadFitRequest(fit, "model");
  if (f.request.model == "guo2006" && !f.request.pair) f.request.pair = std::array<std::string, 2>{"T1", "T2"};
  f.fit_runs = fit.Strings("runs");
  f.compensate_runs = fit.Strings("compensate");
  f.runs_where = fit.Where("runs");
  f.where = FileLine(fit.Where("name"));
  f.compensate_where = fit.Where("compensate");
  if (f.fit_runs.empty()) fit.Fail("runs", "expected the ids of the runs to fit on; an empty list fits on nothing");
  if (f.compensate_runs.empty()) {
    fit.Fail("compensate", "expected the ids of the runs to compensate and check; an empty list checks nothing");
  }
  fit.Finish();
  // A run gets one model: a second fit compensating it is refused here, naming both.
  for (const auto& id : f.compensate_runs) {
    for (const auto& other : earlier) {
      if (std::find(other.compensate_runs.begin(), other.compensate_runs.end(), id) != other.compensate_runs.end()) {
        throw InputError(fmt::format("{}: run '{}' is compensated by two fits, '{}' ({}) and '{}': give each run one "
                                     "fit",
                                     f.compensate_where, id, other.name, FileLine(other.compensate_where), f.name));
      }
    }
    if (std::count(f.compensate_runs.begin(), f.compensate_runs.end(), id) > 1) {
      fit.Fail("compensate", fmt::format("run '{}' is listed twice", id));
    }
  }
  return f;
}

/// The [[checks.limits]] tables of [checks], and the refusal of [checks]' selectors beside them.
void ReadLimitTables(const io::TomlReader& checks, SuiteSpec& s) {
  for (const auto& table : checks.ArrayOfTables("limits")) {
    RunLimits limits;
    limits.prefixes = table.Strings("prefixes");
    limits.where = table.Where("prefixes");
    if (limits.prefixes.empty()) {
      table.Fail("prefixes", "expected the starts of the ids of the runs these limits are for, e.g. [\"ramp\"]");
    }
    for (const auto& prefix : limits.prefixes) {
      if (prefix.empty()) table.Fail("prefixes", "an empty prefix would select every run; name the runs' common start");
    }
    ReadLimits(table, limits);
    table.Finish();
    s.run_limits.push_back(std::move(limits));
  }
  // One way to say which runs get which limits: the tables, or the two selectors of [checks].
  for (const char* key : {"bias_after_runs", "stability_after_runs"}) {
    if (!s.run_limits.empty() && checks.Has(key)) {
      checks.Fail(key, fmt::format("a suite with [[checks.limits]] tables ({}) selects runs by their prefixes only: "
                                   "move these runs' limits into a [[checks.limits]] table",
                                   FileLine(s.run_limits.front().where)));
    }
  }
}

/// [checks]: the limits, the run selectors or the limit tables, the trend and best pair checks,
/// the failing fraction, the baseline's sigma and the yield.
void ReadChecks(const io::TomlReader& checks, SuiteSpec& s) {
  ReadLimits(checks, s.limits);
  auto selector = [&](const char* key, std::optional<std::string>& prefix, std::string& where) {
    if (!checks.Has(key)) return;
    prefix = checks.String(key);
    where = checks.Where(key);
    if (prefix->empty()) {
      checks.Fail(key, "expected the start of the ids of the runs it checks, e.g. \"fixed\"; leave the key out to "
                       "check every compensated run");
    }
  };
  selector("bias_after_runs", s.bias_check_prefix, s.bias_check_where);
  selector("stability_after_runs", s.stability_check_prefix, s.stability_check_where);
  ReadLimitTables(checks, s);
  if (checks.Has("trend_max_sigma")) s.trend_where = KeyLine(checks, "trend_max_sigma");
  s.trend_max_sigma = checks.Positive("trend_max_sigma", 3.0);
  s.expected_best_pair = checks.String("best_pair", "");
  if (checks.Has("best_pair")) {
    s.best_pair_where = KeyLine(checks, "best_pair");
    std::vector<std::string> names;
    for (const auto& c : model::PaperCombinations()) names.push_back(c.name);
    if (std::find(names.begin(), names.end(), s.expected_best_pair) == names.end()) {
      checks.Fail("best_pair", fmt::format("expected one of the paper's pairs {}, found \"{}\"", fmt::join(names, ", "),
                                           s.expected_best_pair));
    }
  }
  s.max_failing_fraction = checks.InRange("max_failing_fraction", 0.0, 1.0, 0.0);
  s.baseline_max_sigma = checks.Positive("baseline_max_sigma", kBaselineMaxSigma);
  if (checks.Has("min_yield")) {
    s.min_yield = checks.InRange("min_yield", 0.0, 1.0);
    s.min_yield_where = KeyLine(checks, "min_yield");
  }
  checks.Finish();
}

/// A [[compensators]] entry: a plug-in, named apart from the fitted models and the others.
PluginCompensator ReadCompensator(const io::TomlReader& table, const std::string& path,
                                  const std::vector<PluginCompensator>& earlier) {
  PluginCompensator p;
  p.name = table.String("name");
  for (const char* reserved : kFittedCompensatorNames) {
    if (p.name.empty() || p.name == reserved) {
      table.Fail("name", "expected a non-empty name other than a fitted model's (eq2, guo2006, poly, px4, ardupilot, auto)");
    }
  }
  for (const auto& other : earlier) {
    if (other.name == p.name) table.Fail("name", fmt::format("a second compensator named '{}'", p.name));
  }
  p.command = table.String("command");
  if (p.command.empty()) table.Fail("command", "expected a shell command, e.g. \"python3 my_comp.py\"");
  p.column = table.String("column", p.column);
  p.directory = std::filesystem::absolute(path).parent_path().lexically_normal().string();
  table.Finish();
  return p;
}

/// [paper]: the paper's Table 1 SSE_ave per pair and its Table 2 values per run.
void ReadPaper(const io::TomlReader& paper, SuiteSpec& s) {
  if (const auto t1 = paper.OptionalTable("table1_sse_ave")) {
    for (const auto& k : t1->Keys()) s.paper_sse_ave[k] = t1->Number(k);
    t1->Finish();
  }
  if (const auto t2 = paper.OptionalTable("table2")) {
    for (const auto& k : t2->Keys()) {
      const auto v = t2->Pairs(k);  // reads [[before, after], [stab before, stab after]]
      if (v.size() != 2) t2->Fail(k, "expected [[bias before, bias after], [stability before, stability after]]");
      s.paper_table2[k] = {v[0].first, v[0].second, v[1].first, v[1].second};
    }
    t2->Finish();
  }
  paper.Finish();
}

}  // namespace

SuiteSpec LoadSuite(const std::string& path) {
  if (!io::IsRegularFile(path)) throw InputError(fmt::format("{}: suite file not found", path));
  const auto doc = io::ParseTomlFile(path);
  const io::TomlReader root(*doc, path, "suite");
  if (root.Has("gyro") && !root.Has("scenarios")) {
    throw InputError(fmt::format("{}: this is a scenario (it names a gyro), not a validate suite: run `rlgtherm "
                                 "simulate {}`; validate reads a suite file (scenarios = [...], [[fits]])",
                                 path, path));
  }
  SuiteSpec s;
  s.path = path;
  const auto dir = std::filesystem::path(path).parent_path();
  for (const auto& rel : root.Strings("scenarios")) s.scenarios.push_back((dir / rel).lexically_normal().string());
  s.scenarios_where = root.Where("scenarios");
  if (s.scenarios.empty()) root.Fail("scenarios", "expected at least one scenario file");
  if (root.Has("seed")) s.seed = static_cast<uint64_t>(root.Integer("seed", 1));
  for (const auto& fit : root.ArrayOfTables("fits")) s.fits.push_back(ReadFit(fit, s.fits));
  if (s.fits.empty()) root.FailHere("a suite needs at least one [[fits]] entry");
  if (const auto pairs = root.OptionalTable("pairs")) {
    if (pairs->Has("runs")) s.pairs_runs = pairs->Strings("runs");
    s.pairs_average_s = pairs->Positive("average_s", 0.0, true);
    pairs->Finish();
  }
  if (s.pairs_runs.empty()) s.pairs_runs = s.fits.front().fit_runs;
  if (const auto comp = root.OptionalTable("compensate")) {
    s.averaging_explicit = comp->Has("averaging_s");
    s.averaging_s = comp->Positive("averaging_s", 1.0);
    comp->Finish();
  }
  if (const auto checks = root.OptionalTable("checks")) ReadChecks(*checks, s);
  for (const auto& table : root.ArrayOfTables("compensators")) {
    s.compensators.push_back(ReadCompensator(table, path, s.compensators));
  }
  if (const auto population = root.OptionalTable("population")) s.population = io::ReadPopulation(*population);
  if (s.min_yield && !s.population) {
    throw InputError(fmt::format("{}: key 'min_yield' in [checks]: a yield is a share of a population's gyros; this "
                                 "suite has no [population]",
                                 s.min_yield_where));
  }
  if (const auto paper = root.OptionalTable("paper")) ReadPaper(*paper, s);
  root.Finish();
  return s;
}

namespace {

// The floor the bias check reports as information: 3 sigma of the B0 window mean (a 0.3 %
// chance for a perfect compensator to exceed it with Gaussian B0 errors).
constexpr double kInformationFloorSigma = 3.0;

/// Where a limit comes from: the key as written ("KEY at FILE:LINE", [checks]'s or a table's),
/// or what the check compares with when it was not written. `limited`: the run is one the
/// limit applies to (a [checks] selector may leave it out).
std::string Source(const RunLimits& limits, const std::string& key, bool limited = true) {
  const auto it = limits.written.find(key);
  if (limited && it != limits.written.end()) return fmt::format("{} at {}", key, it->second);
  if (key == "bias_after_max_dph") return "the default bias_after_max_dph = 0.01 °/h (not written)";
  return fmt::format("the run's own value before compensation ({} not written{})", key,
                     limited ? "" : " for this run");
}

/// A failed check explains itself: by how much it missed, which run and fit, where the limit
/// comes from and where to look (docs/cli.md, validate).
void Explain(const SuiteSpec& spec, Check& c) {
  if (c.value && c.limit && std::isfinite(*c.limit)) {
    const double margin = *c.value - *c.limit;
    c.detail += fmt::format("; over the limit by {:.4g} {}", margin, c.unit);
    if (*c.limit > 0.0) c.detail += fmt::format(" ({:.0f} %)", 100.0 * margin / *c.limit);
  }
  c.detail += fmt::format("; run '{}', compensated by {} of fit '{}'; the limit: {}; look: `rlgtherm validate {} --plot "
                          "DIR` draws the run's bias before and after and its Allan curve",
                          c.run, c.compensator, c.fit, c.source, spec.path);
}

Check BiasCheck(const RunLimits& limits, const RunEvaluation& e) {
  Check c;
  c.name = "bias after";
  c.run = e.run;
  c.unit = "°/h";
  const double value = std::abs(e.bias_after_dph);
  const double written = limits.bias_after_max_dph;
  const double chosen_floor = limits.bias_after_floor_sigma * e.b0_error_dph;  // 0 when the suite asks for none
  c.value = value;
  c.limit = std::max(written, chosen_floor);
  c.passed = value <= *c.limit;
  c.source = Source(limits, chosen_floor > written ? "bias_after_floor_sigma" : "bias_after_max_dph");
  const char* rel = c.passed ? "<=" : ">";
  if (chosen_floor > written) {
    c.detail = fmt::format("|{:+.4f}| {} {:.4f} °/h, the floor the suite chose: {:g} sigma_B0 (sigma_B0 = {:.4f} °/h, the "
                           "error of the B0 window mean); bias_after_max_dph = {:g} °/h {}",
                           e.bias_after_dph, rel, chosen_floor, limits.bias_after_floor_sigma, e.b0_error_dph, written,
                           value <= written ? "met" : fmt::format("missed by {:.4f}", value - written));
  } else {
    c.detail = fmt::format("|{:+.4f}| {} {:g} °/h, {}", e.bias_after_dph, rel, written,
                           limits.written.count("bias_after_max_dph") ? "the limit written" : "the default limit");
    // Beside a pass, how close the noise of the B0 window mean comes to the limit.
    if (c.passed) c.detail += fmt::format(" (B0-window floor {:g} sigma = {:.4f} °/h)", kInformationFloorSigma,
                                          kInformationFloorSigma * e.b0_error_dph);
  }
  return c;
}

Check StabilityCheck(const std::string& name, const RunEvaluation& e, const model::Stability& before,
                     const model::Stability& after, std::optional<double> limit) {
  Check c;
  c.name = name;
  c.run = e.run;
  c.unit = "°/h";
  c.value = after.sigma;
  const std::string at = model::DescribeAveraging(after, e.sample_period_s);
  if (limit) {
    c.limit = *limit;
    c.passed = after.sigma <= *limit;
    c.detail = fmt::format("at {}: after {:.4f} {} {:g} °/h, the limit written (before {:.4f})", at, after.sigma,
                           c.passed ? "<=" : ">", *limit, before.sigma);
  } else {
    c.limit = before.sigma;
    c.passed = after.sigma <= before.sigma;
    c.detail = fmt::format("at {}: {:.4f} -> {:.4f} °/h, after {} before", at, before.sigma, after.sigma,
                           c.passed ? "<=" : ">");
  }
  return c;
}

Check PeakCheck(const RunEvaluation& e, std::optional<double> limit) {
  Check c;
  c.name = "peak 100s";
  c.run = e.run;
  c.unit = "°/h";
  c.value = e.peak_abs_100s_after_dph;
  if (limit) {
    c.limit = *limit;
    c.passed = e.peak_abs_100s_after_dph <= *limit;
    c.detail = fmt::format("largest |100 s mean| after {:.4f} {} {:g} °/h, the limit written (run mean {:+.4f})",
                           e.peak_abs_100s_after_dph, c.passed ? "<=" : ">", *limit, e.bias_after_dph);
  } else {
    c.limit = e.peak_abs_100s_before_dph;
    c.passed = e.peak_abs_100s_after_dph <= e.peak_abs_100s_before_dph;
    c.detail = fmt::format("largest |100 s mean|: {:.4f} -> {:.4f} °/h, after {} before (no limit written)",
                           e.peak_abs_100s_before_dph, e.peak_abs_100s_after_dph, c.passed ? "<=" : ">");
  }
  return c;
}

Check TrendCheck(const SuiteSpec& spec, const RunEvaluation& e) {
  Check c;
  c.name = "trend";
  c.run = e.run;
  c.unit = "°/h/°C";
  c.value = std::abs(e.trend_dph_per_C);
  c.limit = spec.trend_max_sigma * e.trend_stderr_dph_per_C;
  c.passed = !(*c.value > *c.limit);  // an infinite standard error (no temperature change) passes
  c.detail = fmt::format("|{:+.5f}| {} {:.5f} °/h/°C, the limit written: {:g} standard errors of {:.5f}",
                         e.trend_dph_per_C, c.passed ? "<=" : ">", *c.limit, spec.trend_max_sigma,
                         e.trend_stderr_dph_per_C);
  return c;
}

/// Every [[checks.limits]] prefix starts a compensated run, no run is selected by two tables,
/// and no limit of [checks] is left for no run (every run in a table): else InputError naming
/// the lines.
void CheckLimitTables(const SuiteSpec& spec) {
  if (spec.run_limits.empty()) return;
  std::vector<std::string> compensated;
  for (const auto& fit : spec.fits) compensated.insert(compensated.end(), fit.compensate_runs.begin(), fit.compensate_runs.end());
  for (const auto& table : spec.run_limits) {
    for (const auto& prefix : table.prefixes) {
      if (std::none_of(compensated.begin(), compensated.end(), [&](const std::string& id) { return id.rfind(prefix, 0) == 0; })) {
        throw InputError(fmt::format("{}: \"{}\" starts the id of no compensated run ({}): its limits would check nothing",
                                     table.where, prefix, fmt::join(compensated, ", ")));
      }
    }
  }
  bool every_run_in_a_table = true;
  for (const auto& id : compensated) {
    std::vector<const RunLimits*> selecting;
    for (const auto& table : spec.run_limits)
      if (table.Selects(id)) selecting.push_back(&table);
    if (selecting.size() > 1) {
      throw InputError(fmt::format("{}: run '{}' is selected by this [[checks.limits]] table and by the one at {}: give "
                                   "each run one table, so that its limits are not ambiguous",
                                   selecting[1]->where, id, FileLine(selecting[0]->where)));
    }
    every_run_in_a_table = every_run_in_a_table && !selecting.empty();
  }
  if (every_run_in_a_table && !spec.limits.written.empty()) {
    const auto& [key, where] = *spec.limits.written.begin();
    throw InputError(fmt::format("{}: key '{}' in [checks] is for the runs no [[checks.limits]] table selects, and "
                                 "there are none (every compensated run is in a table): write it in the tables",
                                 where, key));
  }
}

/// The largest |dT| over `runs` (dT = Ti - Ti0, Ti0 the run's first Ti), and the runs.
struct RiseSpan {
  double rise_C = 0.0;
  std::vector<const sim::Run*> runs;
};
RiseSpan Rise(const model::Guo2006Coefficients& c, const std::vector<const sim::Run*>& runs) {
  RiseSpan span;
  span.runs = runs;
  for (const sim::Run* r : runs) {
    // |T - T0| is largest at the highest or the lowest T (a rounded difference is monotonic
    // in T), so the extremes give the same value as a scan of |T - T0|; four of each, side by
    // side, so that no comparison waits on the one before (NaNs are passed over either way).
    const auto& Ti = r->Column(c.pair[0]);
    if (Ti.empty()) continue;
    std::array<double, 4> lo, hi;
    lo.fill(Ti.front());
    hi.fill(Ti.front());
    size_t i = 0;
    for (; i + 4 <= Ti.size(); i += 4) {
      for (size_t j = 0; j < 4; ++j) {
        lo[j] = std::min(lo[j], Ti[i + j]);
        hi[j] = std::max(hi[j], Ti[i + j]);
      }
    }
    for (; i < Ti.size(); ++i) {
      lo[0] = std::min(lo[0], Ti[i]);
      hi[0] = std::max(hi[0], Ti[i]);
    }
    for (size_t j = 0; j < 4; ++j) {
      span.rise_C = std::max({span.rise_C, std::abs(hi[j] - Ti.front()), std::abs(lo[j] - Ti.front())});
    }
  }
  return span;
}

/// The largest |B - B0| Eq. (2) predicts over `runs`: for a warning's text only, so computed
/// only when one is written (a prediction per sample is ~5 % of a population gyro's CPU).
double PeakPrediction(const model::Guo2006Coefficients& c, const std::vector<const sim::Run*>& runs) {
  double peak = 0.0;
  for (const sim::Run* r : runs) {
    const auto& Ti = r->Column(c.pair[0]);
    const auto& Tj = r->Column(c.pair[1]);
    for (size_t i = 0; i < Ti.size(); ++i) peak = std::max(peak, std::abs(c.Predict(Ti[i], Tj[i], Ti.front())));
  }
  return peak;
}

/// The warnings of one compensated run (SuiteReport::evaluation_warnings).
std::vector<std::string> ExtrapolationWarnings(const SuiteFit& fit, const model::FittedModel& fitted,
                                               const std::optional<RiseSpan>& fitted_rise, const sim::Run& run,
                                               const RunEvaluation& e) {
  std::vector<std::string> out;
  if (const auto* c = std::get_if<model::Guo2006Coefficients>(&fitted)) {
    if (e.outside_fitted_range) {
      out.push_back(fmt::format("{}: Ti0 = {:.2f} °C is outside the range {:.2f} ... {:.2f} °C fit '{}' was fitted "
                                "on (extrapolated)",
                                run.Where(), e.Ti0_C, c->t10_range_C[0], c->t10_range_C[1], fit.name));
    }
    const RiseSpan here = Rise(*c, {&run});
    if (fitted_rise && here.rise_C > kFarBeyondFittedRise * fitted_rise->rise_C) {
      out.push_back(fmt::format("{}: its temperature rise dT = {} - Ti0 reaches {:.1f} °C, {:.0f}x the largest of fit "
                                "'{}' ({:.2f} °C): Eq. (2)'s dT and dT² terms are extrapolated and predict up to {:.3g} "
                                "°/h here, {:.3g} °/h at most on the runs they were fitted on",
                                run.Where(), c->pair[0], here.rise_C, here.rise_C / fitted_rise->rise_C, fit.name,
                                fitted_rise->rise_C, PeakPrediction(*c, here.runs), PeakPrediction(*c, fitted_rise->runs)));
    }
  } else if (e.outside_fitted_range) {
    const auto& p = std::get<model::PolyModel>(fitted);
    out.push_back(compensation::OutsideRangeWarning(p, run, compensation::SamplesOutsideFittedRange(fitted, run)) +
                  fmt::format(" (fit '{}')", fit.name));
  }
  return out;
}

}  // namespace

void AddCompensatedRun(const SuiteSpec& spec, size_t fit, const sim::Run& run, const std::string& compensator,
                       std::vector<double> compensated, SuiteReport& rep,
                       const std::function<std::vector<std::string>(const RunEvaluation&)>& warn) {
  EvaluationOptions options;
  options.averaging_s = spec.averaging_s;
  options.averaging_explicit = spec.averaging_explicit;
  RunEvaluation e;
  try {
    e = EvaluateRun(run, compensated, rep.models.at(fit), options);
  } catch (const InputError& err) {
    throw InputError(fmt::format("{}: {}", spec.path, err.what()));
  }
  rep.evaluations.push_back(e);
  rep.evaluation_fit.push_back(spec.fits.at(fit).name);
  rep.evaluation_compensator.push_back(compensator);
  rep.compensated.push_back(std::move(compensated));
  rep.evaluation_warnings.push_back(warn ? warn(e) : std::vector<std::string>{});
  const size_t first_check = rep.checks.size();
  // The run's limits: its [[checks.limits]] table's, else [checks]'s as its selectors say.
  const auto table = std::find_if(spec.run_limits.begin(), spec.run_limits.end(),
                                  [&](const RunLimits& l) { return l.Selects(run.id); });
  const RunLimits& limits = table != spec.run_limits.end() ? *table : spec.limits;
  const bool in_table = table != spec.run_limits.end();
  const bool bias = in_table || !spec.bias_check_prefix || run.id.rfind(*spec.bias_check_prefix, 0) == 0;
  const bool limited = in_table || !spec.stability_check_prefix || run.id.rfind(*spec.stability_check_prefix, 0) == 0;
  if (bias) rep.checks.push_back(BiasCheck(limits, e));
  rep.checks.push_back(StabilityCheck("stability", e, e.stability_before, e.stability_after,
                                      limited ? limits.stability_after_max_dph : std::nullopt));
  rep.checks.back().source = Source(limits, "stability_after_max_dph", limited);
  rep.checks.push_back(StabilityCheck("stability 100s", e, e.stability_100s_before, e.stability_100s_after,
                                      limited ? limits.stability_100s_after_max_dph : std::nullopt));
  rep.checks.back().source = Source(limits, "stability_100s_after_max_dph", limited);
  rep.checks.push_back(PeakCheck(e, limited ? limits.peak_abs_100s_after_max_dph : std::nullopt));
  rep.checks.back().source = Source(limits, "peak_abs_100s_after_max_dph", limited);
  rep.checks.push_back(TrendCheck(spec, e));
  rep.checks.back().source = spec.trend_where.empty() ? "the default trend_max_sigma = 3 (not written)"
                                                      : fmt::format("trend_max_sigma at {}", spec.trend_where);
  for (size_t c = first_check; c < rep.checks.size(); ++c) {
    rep.checks[c].compensator = compensator;
    rep.checks[c].fit = spec.fits.at(fit).name;
    rep.checks[c].warnings = rep.evaluation_warnings.back();
    if (!rep.checks[c].passed) Explain(spec, rep.checks[c]);
  }
}

bool SuiteReport::passed() const {
  return std::all_of(checks.begin(), checks.end(), [](const Check& c) { return c.passed; });
}

std::vector<sim::Scenario> LoadSuiteScenarios(const SuiteSpec& spec) {
  std::vector<sim::Scenario> out;
  for (const auto& path : spec.scenarios) {
    try {
      out.push_back(io::LoadScenario(path));
    } catch (const InputError& e) {
      // Which line of the suite brought the file in, then what is wrong with it.
      throw InputError(fmt::format("{}: {}", spec.scenarios_where, e.what()));
    }
  }
  return out;
}

namespace {

using Progress = std::function<void(const std::string&)>;

/// The suite's scenarios simulated, on `gyro` when given, with `seed`, else the suite's seed,
/// else each scenario's: their runs in `trace`, no id in two scenarios. The runs `trace` holds
/// are replaced, their buffers reused (sim::SimulateScenario's reuse path).
void SimulateScenarios(const SuiteSpec& spec, const std::vector<sim::Scenario>& scenarios, const sim::GyroConfig* gyro,
                       std::optional<uint64_t> seed, const Progress& progress, const sim::SensorChannels& channels,
                       sim::Trace& trace) {
  std::set<std::string> ids;
  size_t runs = 0;  // reserved: a growing vector of Runs copies them (sim::SimulateScenario)
  for (const auto& loaded : scenarios) runs += loaded.runs.size();
  std::vector<sim::Run> spare = std::move(trace.runs);
  trace.runs.clear();
  trace.runs.reserve(runs);
  size_t next_spare = 0;
  for (const auto& loaded : scenarios) {
    const sim::Scenario* scenario = &loaded;
    sim::Scenario replaced;
    if (gyro) {
      replaced = loaded;
      replaced.gyro = *gyro;
      scenario = &replaced;
    }
    const sim::Scenario& sc = *scenario;
    sim::Trace t;
    t.runs.reserve(sc.runs.size());
    for (; t.runs.size() < sc.runs.size() && next_spare < spare.size(); ++next_spare) {
      t.runs.push_back(std::move(spare[next_spare]));
    }
    // What `simulate` would refuse to write is not evaluated either: a temperature beyond the
    // plausible range (a source's power mistyped 1e4 W) gives numbers, but not a gyro's.
    const auto readable = [&sc](size_t i, const sim::Run& run) { sim::CheckReadable(sc, i, run); };
    sim::SimulateScenario(sc, seed.value_or(spec.seed.value_or(sc.seed)), [&](size_t i, size_t) {
      if (progress) progress(fmt::format("simulating {}", sc.runs[i].id));
    }, channels, &t, readable);
    for (auto& r : t.runs) {
      if (!ids.insert(r.id).second) throw InputError(fmt::format("{}: run id '{}' appears in two scenarios", spec.path, r.id));
      trace.runs.push_back(std::move(r));
    }
  }
}

/// Every run a fit names is simulated, and every selector matches a compensated run: nothing
/// the suite asks for is dropped silently (InputError naming the line).
void CheckWhatTheSuiteNames(const SuiteSpec& spec, const sim::Trace& trace) {
  for (const auto& fit : spec.fits) {
    for (const auto* list : {&fit.fit_runs, &fit.compensate_runs}) {
      for (const auto& id : *list) {
        const bool known = std::any_of(trace.runs.begin(), trace.runs.end(), [&](const sim::Run& r) { return r.id == id; });
        if (!known) {
          std::vector<std::string> ids;
          for (const auto& r : trace.runs) ids.push_back(r.id);
          throw InputError(fmt::format("{}: run '{}' is in none of the suite's scenarios (runs: {})",
                                       list == &fit.fit_runs ? fit.runs_where : fit.compensate_where, id,
                                       fmt::join(ids, ", ")));
        }
      }
    }
  }
  auto check_selector = [&](const std::optional<std::string>& prefix, const std::string& where) {
    if (!prefix) return;
    std::vector<std::string> compensated;
    for (const auto& fit : spec.fits)
      for (const auto& id : fit.compensate_runs)
        if (id.rfind(*prefix, 0) == 0) return;
    for (const auto& fit : spec.fits) compensated.insert(compensated.end(), fit.compensate_runs.begin(), fit.compensate_runs.end());
    throw InputError(fmt::format("{}: \"{}\" starts the id of no compensated run ({}): its checks would check nothing",
                                 where, *prefix, fmt::join(compensated, ", ")));
  };
  check_selector(spec.bias_check_prefix, spec.bias_check_where);
  check_selector(spec.stability_check_prefix, spec.stability_check_where);
  CheckLimitTables(spec);
}

/// The suite's fits, in order, into rep.models; per fit, its runs' dT span (Eq. (2) only); and
/// the fit that compensates each run.
struct SuiteFits {
  std::map<std::string, size_t> fit_of_run;
  std::vector<std::optional<RiseSpan>> fitted_rise;
};
SuiteFits FitSuite(const SuiteSpec& spec, SuiteReport& rep, const Progress& progress) {
  SuiteFits out;
  for (size_t f = 0; f < spec.fits.size(); ++f) {
    if (progress) progress(fmt::format("fitting {}", spec.fits[f].name));
    // A fit that fails (exit 2 for its data, 3 when the data cannot identify it) names the fit
    // and the line of the suite that defines it.
    const std::string fit_where = fmt::format("{}: fit '{}'", spec.fits[f].where, spec.fits[f].name);
    try {
      rep.models.push_back(model::FitModel(rep.trace.Select(spec.fits[f].fit_runs), spec.fits[f].request));
    } catch (const NumericalError& e) {
      throw NumericalError(fmt::format("{}: {}", fit_where, e.what()));
    } catch (const InputError& e) {
      throw InputError(fmt::format("{}: {}", fit_where, e.what()));
    }
    out.fitted_rise.emplace_back();
    if (const auto* c = std::get_if<model::Guo2006Coefficients>(&rep.models.back())) {
      out.fitted_rise.back() = Rise(*c, rep.trace.Select(spec.fits[f].fit_runs));
    }
    for (const auto& id : spec.fits[f].compensate_runs) out.fit_of_run.emplace(id, f);  // one fit per run: LoadSuite
  }
  return out;
}

/// Table 1: the sensor pairs scored on the runs of [pairs] (block means of average_s when given).
void ScoreSuitePairs(const SuiteSpec& spec, SuiteReport& rep, const Progress& progress) {
  if (progress) progress("scoring sensor pairs");
  const std::vector<const sim::Run*> selected = rep.trace.Select(spec.pairs_runs);
  std::vector<sim::Run> averaged;
  averaged.reserve(selected.size());
  for (const auto* r : selected)
    averaged.push_back(spec.pairs_average_s > 0 ? sim::BlockMeans(*r, spec.pairs_average_s) : *r);
  std::vector<const sim::Run*> pair_runs;
  for (const auto& r : averaged) pair_runs.push_back(&r);
  // Table 1 is Eq. (2)'s: with the first fit's method and B0 window when it is Eq. (2).
  model::FitOptions pair_options;
  const model::FitRequest& first = spec.fits.front().request;
  pair_options.b0_window_s = first.b0_window_s;
  if (first.model == "guo2006" && first.method) {
    pair_options.method = model::ParseGuo2006Method(*first.method).value_or(model::Guo2006Method::kJoint);
  }
  rep.pairs = model::ScorePairs(pair_runs, model::PaperCombinations(), pair_options);
}

/// Each compensated run through its fit's model, then through each plug-in: the same
/// evaluation and the same checks (AddCompensatedRun).
void CompensateSuite(const SuiteSpec& spec, const SuiteFits& fits, SuiteReport& rep, const Progress& progress) {
  for (const auto& run : rep.trace.runs) {
    const auto assigned = fits.fit_of_run.find(run.id);
    if (assigned == fits.fit_of_run.end()) continue;  // a training run only
    const model::FittedModel& fitted = rep.models[assigned->second];
    if (progress) progress(fmt::format("compensating {}", run.id));
    for (size_t k = 0; k <= spec.compensators.size(); ++k) {
      const std::string compensator = k == 0 ? spec.fits[assigned->second].Compensator() : spec.compensators[k - 1].name;
      if (progress && k > 0) progress(fmt::format("compensating {} with {}", run.id, compensator));
      std::vector<double> comp;
      try {
        comp = k == 0 ? CompensateRun(fitted, run) : RunPlugin(spec.compensators[k - 1], run);
      } catch (const InputError& err) {
        throw InputError(fmt::format("{}: {}", spec.path, err.what()));
      }
      // A plug-in's output is not the fitted model's: its extrapolation is the plug-in's own affair.
      const auto warn = [&](const RunEvaluation& e) {
        return ExtrapolationWarnings(spec.fits[assigned->second], fitted, fits.fitted_rise[assigned->second], run, e);
      };
      AddCompensatedRun(spec, assigned->second, run, compensator, std::move(comp), rep,
                        k == 0 ? std::function<std::vector<std::string>(const RunEvaluation&)>(warn) : nullptr);
    }
  }
}

/// The best pair of Table 1 against the one [checks] best_pair expects.
Check BestPairCheck(const SuiteSpec& spec, const std::vector<model::PairScore>& pairs) {
  const auto& best = model::BestPair(pairs);
  Check c;
  c.name = "best pair";
  c.passed = best.combination.name == spec.expected_best_pair;
  c.detail = fmt::format("{} (SSE_ave {:.4f}), expected {}", best.combination.name, best.sse_ave, spec.expected_best_pair);
  c.source = fmt::format("best_pair at {}", spec.best_pair_where);
  if (!c.passed) {
    c.detail += fmt::format("; the limit: {}; look: Table 1 (SSE_ave of each pair, on the runs of [pairs])", c.source);
  }
  return c;
}

}  // namespace

SuiteReport RunSuite(const SuiteSpec& spec, const std::function<void(const std::string&)>& progress) {
  return RunSuite(spec, LoadSuiteScenarios(spec), nullptr, std::nullopt, progress);
}

sim::SensorChannels ChannelsRead(const SuiteSpec& spec) {
  if (!spec.expected_best_pair.empty() || !spec.compensators.empty()) return {};
  sim::SensorChannels read;
  for (const auto& fit : spec.fits) {
    const model::FitRequest& r = fit.request;
    // Eq. (2) reads its pair (its fit, compensation, rise and trend); any other model is let
    // read every channel.
    if (!(r.model.empty() || r.model == "guo2006") || !r.pair) return {};
    for (const auto& channel : *r.pair) read.only.push_back(channel);
  }
  return read;
}

SuiteReport RunSuite(const SuiteSpec& spec, const std::vector<sim::Scenario>& scenarios, const sim::GyroConfig* gyro,
                     std::optional<uint64_t> seed, const std::function<void(const std::string&)>& progress,
                     PairScoring pairs, const sim::SensorChannels& channels, std::vector<sim::Run> recycled) {
  SuiteReport rep;
  rep.trace.runs = std::move(recycled);
  SimulateScenarios(spec, scenarios, gyro, seed, progress, channels, rep.trace);
  CheckWhatTheSuiteNames(spec, rep.trace);
  const SuiteFits fits = FitSuite(spec, rep, progress);
  if (pairs == PairScoring::kAlways || !spec.expected_best_pair.empty()) ScoreSuitePairs(spec, rep, progress);
  CompensateSuite(spec, fits, rep, progress);
  if (!spec.expected_best_pair.empty()) rep.checks.push_back(BestPairCheck(spec, rep.pairs));
  return rep;
}

}  // namespace rlg::validation
