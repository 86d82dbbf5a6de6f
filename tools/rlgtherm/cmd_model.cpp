// Verbs fit (every model of the family), pairs and allan.

#include <CLI/CLI.hpp>
#include <cmath>
#include <fmt/format.h>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>

#include "model/allan.h"
#include "model/coefficients_json.h"
#include "model/fit_model.h"
#include "model/linear_fit.h"
#include "model/pairs.h"
#include "sim/errors.h"
#include "tools/rlgtherm/commands.h"
#include "tools/rlgtherm/common.h"
#include "tools/rlgtherm/verb_figures.h"

namespace rlg::cli {
namespace {

/// --method's refusal, naming the option as given (model::FitModel would refuse it as "method").
void RefuseUnknownMethod(const std::string& m) {
  if (!model::ParseGuo2006Method(m)) throw InputError(fmt::format("--method '{}': expected joint or two_stage", m));
}

/// The paper's M1..M6 need T1..T4: say which channels a run lacks, which combinations that
/// rules out, and that --all scores the pairs the data can form.
void RequireChannels(const std::vector<const sim::Run*>& runs,
                     const std::vector<model::PairCombination>& combos) {
  for (const sim::Run* r : runs) {
    const std::vector<std::string> missing = model::MissingChannels(*r, combos);
    if (missing.empty()) continue;
    std::vector<std::string> lost;
    for (const auto& c : combos)
      for (const auto& ch : missing)
        if (c.pair[0] == ch || c.pair[1] == ch) {
          lost.push_back(c.name);
          break;
        }
    throw InputError(fmt::format(
        "{} has no {} {}, so the paper's combination{} {} cannot be formed; --all scores every ordered "
        "pair of the temperature channels present ({})",
        r->Where(), missing.size() == 1 ? "channel" : "channels", fmt::join(missing, ", "),
        lost.size() == 1 ? "" : "s", fmt::join(lost, ", "), fmt::join(model::TemperatureChannels(*r), ", ")));
  }
}

}  // namespace

namespace {

/// Eq. (2), as `fit` has always printed it.
int PrintEquation2(const FitArgs& a, const model::Guo2006Coefficients& c) {
  const nlohmann::json j = model::ToJson(c);
  if (!a.out.empty()) WriteText(a.out, j.dump(2) + "\n");
  if (a.out == "-") return 0;
  if (a.json) {
    fmt::print("{}\n", j.dump(2));
    return 0;
  }
  fmt::print("Eq. (2) fit ({}), pair ({}, {}), {} runs, Ti0 {:.2f} ... {:.2f} °C\n", model::Guo2006MethodName(c.method), c.pair[0],
             c.pair[1],              c.runs.size(), c.t10_range_C[0], c.t10_range_C[1]);
  fmt::print("  a_k = A_k0 + A_k1 Ti0 + A_k2 Ti0²   (± 95 % confidence half-width; standard errors in --json)\n");
  const Eigen::Matrix3d hw = c.ConfidenceHalfWidth(0.95);
  const char* terms[3] = {"dT  ", "dT² ", "Tj-Ti"};
  for (int k = 0; k < 3; ++k) {
    fmt::print("  a{} ({}):", k + 1, terms[k]);
    for (int l = 0; l < 3; ++l) fmt::print("  {:+.4e} ± {:.1e}", c.A(k, l), hw(k, l));
    fmt::print("\n");
  }
  const double dof_lo = c.stderr_dof.minCoeff(), dof_hi = c.stderr_dof.maxCoeff();
  fmt::print("  intervals from {}, Student's t with {} degrees of freedom\n",
             c.stderr_method == "run_scatter"
                 ? "the scatter of the runs about the fit (slow noise such as bias instability included)"
                 : "the within-run residuals assuming white noise (3 runs leave no scatter; 4 or more would "
                   "include bias instability)",
             dof_hi - dof_lo < 0.05 ? fmt::format("{:.3g}", dof_lo) : fmt::format("{:.3g} to {:.3g}", dof_lo, dof_hi));
  fmt::print("  scaled condition number {:.3g}, residual RMS {:.4f} °/h{}\n", c.condition_number, c.residual_rms_dph,
             a.out.empty() ? "" : fmt::format(", written to {}", a.out));
  return 0;
}

/// The polynomial models: poly, px4, ardupilot, auto.
int PrintPolynomial(const FitArgs& a, const model::PolyModel& m) {
  const nlohmann::json j = model::ToJson(m);
  if (!a.out.empty()) WriteText(a.out, j.dump(2) + "\n");
  if (a.out == "-") return 0;
  if (a.json) {
    fmt::print("{}\n", j.dump(2));
    return 0;
  }
  const model::PolySpec& s = m.spec;
  fmt::print("{} fit: {}, {} run{}, {} spans {:.2f} ... {:.2f} °C ({} when applied), T_ref {:.2f} °C{}\n",
             model::PolyPresetName(m.preset), s.Describe(), m.runs.size(), m.runs.size() == 1 ? "" : "s", s.channel, s.range_C[0], s.range_C[1],
             s.extrapolate ? "extrapolated beyond it" : "clipped to it", s.reference_C,
             s.offset == model::OffsetRule::kPowerOn ? fmt::format(", B0 over the first {:g} s", s.b0_window_s) : "");
  for (const auto& t : s.terms) {
    if (t.kind == model::TermKind::kHysteresis) fmt::print("  hysteresis width w = {:.4g} °C (profile search)\n", t.width_C);
    if (t.kind == model::TermKind::kLag) fmt::print("  lag time constant tau = {:.4g} s (profile search)\n", t.tau_s);
    if (t.kind == model::TermKind::kRate || t.HasRate()) {
      fmt::print("  {} low-pass tau_r = {:.4g} s (ten sample periods)\n", t.kind == model::TermKind::kRate ? "rate" : t.Name(), t.tau_s);
    }
  }
  fmt::print("  {:<14} {:>13} {:>11} {:>10} {:>6}  {}\n", "coefficient", "value", "± 95 %", "stderr", "dof", "unit");
  for (const auto& c : m.coefficients) {
    fmt::print("  {:<14} {:>+13.5e} {:>11.2e} {:>10.2e} {:>6.3g}  {}\n", c.name, c.value,
               model::StudentQuantile(0.95, c.dof) * c.standard_error, c.standard_error, c.dof, c.unit);
  }
  fmt::print("  errors cluster-robust over {} {}{} (Student's t at each coefficient's dof; at the fitted tau and w); "
             "scaled condition number {:.3g}, residual RMS {:.4f} °/h{}\n",
             m.clusters, m.stderr_method == "cluster_runs" ? "runs" : "contiguous blocks of the runs",
             s.offset == model::OffsetRule::kPowerOn ? ", and B0's error by batch means" : "", m.condition_number,
             m.residual_rms_dph, a.out.empty() ? "" : fmt::format(", written to {}", a.out));
  if (m.selection) {
    fmt::print("  selection ({}):\n", m.selection->rule);
    for (const auto& st : m.selection->steps) {
      fmt::print("    {} {:<48} CV RMS {}{}\n", st.accepted ? "+" : " ", st.candidate,
                 std::isfinite(st.cv_rms_dph) ? fmt::format("{:.5f} °/h", st.cv_rms_dph) : "-",
                 st.note.empty() ? "" : "  (" + st.note + ")");
    }
  }
  return 0;
}

}  // namespace

int RunFit(const FitArgs& a) {
  const sim::Trace trace = LoadData(a.data);
  std::vector<const sim::Run*> chosen = trace.Select(a.runs);
  std::vector<sim::Run> heads;  // --until: each run before the cut, from its power-on
  if (a.until_s) {
    if (!(*a.until_s > 0.0)) throw InputError(fmt::format("--until {:g}: expected a time after the runs' first samples (s)", *a.until_s));
    for (const sim::Run* r : chosen) {
      heads.push_back(sim::Head(*r, sim::FirstSampleAt(*r, *a.until_s)));
      if (heads.back().size() < 2) {
        throw InputError(fmt::format("{}: --until {:g} s leaves fewer than two samples to fit", r->Where(), *a.until_s));
      }
    }
    chosen = sim::Pointers(heads);
  }
  model::FitRequest r = a.request;
  if (a.pair_given) r.pair = ParsePair(a.pair);
  if (a.method_given) r.method = a.method;
  const std::string name = model::ResolveModelName(r, chosen);
  model::CheckFitRequest(name, r);  // a usage error, before the data are fitted
  if (name == "guo2006") RefuseUnknownMethod(a.method);
  const model::FittedModel m = model::FitRequested(chosen, r, a.average_s, a.data);
  if (const auto* c = std::get_if<model::Guo2006Coefficients>(&m)) return PrintEquation2(a, *c);
  return PrintPolynomial(a, std::get<model::PolyModel>(m));
}

int RunPairs(const PairsArgs& a) {
  const sim::Trace trace = LoadData(a.data);
  const auto selected = trace.Select(a.runs);
  const auto runs = sim::BlockAveraged(selected, a.average_s);
  model::FitOptions o;
  o.b0_window_s = a.b0_window_s;
  const auto combos = a.all ? model::AllOrderedPairs(*selected.front()) : model::PaperCombinations();
  if (combos.empty()) {
    throw InputError(fmt::format("{}: run '{}' has fewer than two temperature channels (T1, T2, ...): no pair to score",
                                 a.data, selected.front()->id));
  }
  if (!a.all) RequireChannels(selected, combos);
  const auto scores = NamingFile(a.data, [&] { return model::ScorePairs(Pointers(runs), combos, o); });
  const auto& best = model::BestPair(scores);
  if (a.json) {
    nlohmann::json j;
    nlohmann::json& combinations = j["combinations"] = nlohmann::json::object();
    for (const auto& s : scores) {
      nlohmann::json per_run = nlohmann::json::object();
      for (const auto& [id, sse] : s.per_run) per_run[id] = sse;
      combinations[s.combination.name] = {{"pair", {s.combination.pair[0], s.combination.pair[1]}},
                                          {"per_run", per_run},
                                          {"sse_ave", s.sse_ave}};
    }
    j["best"] = best.combination.name;
    j["average_s"] = a.average_s;
    fmt::print("{}\n", j.dump(2));
    return 0;
  }
  fmt::print("SSE (Eq. 3, (°/h)²) per run and model{}\n",
             a.average_s > 0 ? fmt::format(", on {:g} s means", a.average_s) : "");
  fmt::print("{:<12}", "run");
  for (const auto& s : scores) fmt::print(" {:>10}", s.combination.name);
  fmt::print("\n");
  for (size_t r = 0; r < runs.size(); ++r) {
    fmt::print("{:<12}", runs[r].id);
    for (const auto& s : scores) fmt::print(" {:>10.4f}", s.per_run[r].second);
    fmt::print("\n");
  }
  fmt::print("{:<12}", "SSE_ave");
  for (const auto& s : scores) fmt::print(" {:>10.4f}", s.sse_ave);
  fmt::print("\nbest: {} ({}, {})\n", best.combination.name, best.combination.pair[0], best.combination.pair[1]);
  return 0;
}

int RunAllan(const AllanArgs& a) {
  std::optional<FigureDirectory> figures;
  if (!a.plot.empty()) figures.emplace(a.plot);
  const bool raw = a.column == "bias_dph";
  const sim::Trace trace = LoadData(a.data, raw, raw ? std::vector<std::string>{} : std::vector<std::string>{a.column});
  const auto runs = trace.Select(a.run.empty() ? std::vector<std::string>{} : std::vector<std::string>{a.run});
  // Every run is checked before anything is printed: no partial table on a refusal.
  for (const auto* r : runs)
    if (r->size() < 18) throw InputError(fmt::format("{}: {} samples are too few for an Allan deviation", r->Where(), r->size()));
  // Everything is computed (and drawn) before anything is printed.
  std::vector<std::string> ids;
  std::vector<double> periods;
  std::vector<model::AllanCurve> curves;
  std::vector<model::NoiseReadOffs> readoffs;
  for (const auto* r : runs) {
    ids.push_back(r->id);
    periods.push_back(model::SamplePeriod(r->t_s));
    curves.push_back(model::OverlappingAllan(r->Column(a.column), periods.back()));
    readoffs.push_back(model::ReadNoiseTerms(curves.back()));
    if (figures) figures->WriteAllan(r->id, a.column, curves.back(), readoffs.back());
  }
  if (figures) figures->Commit();
  using model::NoiseTerm;
  if (a.json) {
    nlohmann::json j;
    j["column"] = a.column;
    j["runs"] = nlohmann::json::array();
    for (size_t i = 0; i < ids.size(); ++i) {
      nlohmann::json run = {{"run", ids[i]}, {"sample_period_s", periods[i]}, {"tau_s", curves[i].tau_s}, {"adev_dph", curves[i].adev}};
      model::AddNoiseTermsJson(readoffs[i], run);
      j["runs"].push_back(run);
    }
    fmt::print("{}\n", j.dump(2));
    return 0;
  }
  fmt::print("Allan deviation read-offs of {} (IEEE Std 952: N = sigma at 1 s on the -1/2 line, B = floor / 0.664, "
             "K = sigma at 3 s on the +1/2 line; fitted jointly; a term is read only where the curve shows it)\n",
             a.column);
  fmt::print("{:<12} {:>24} {:>24} {:>24} {:>10} {:>10}\n", "run", "ARW °/√h", "bias instab. °/h", "RRW °/h/√h", "dt s",
             "tau max s");
  for (size_t i = 0; i < ids.size(); ++i) {
    const model::NoiseReadOffs& t = readoffs[i];
    fmt::print("{:<12} {:>24} {:>24} {:>24} {:>10g} {:>10g}\n", ids[i], model::FormatReadOff(t, NoiseTerm::kArw, 5),
               model::FormatReadOff(t, NoiseTerm::kBiasInstability, 5), model::FormatReadOff(t, NoiseTerm::kRrw, 5),
               periods[i], curves[i].tau_s.back());
  }
  for (const auto& note : model::NotResolvedNotes(ids, readoffs, {NoiseTerm::kArw, NoiseTerm::kBiasInstability, NoiseTerm::kRrw})) {
    fmt::print("  {}\n", note);
  }
  return 0;
}

Verb RegisterFit(CLI::App& app) {
  auto a = std::make_shared<FitArgs>();
  CLI::App* cmd = app.add_subcommand("fit",
                                     "fit a compensation model: the paper's Eq. (2) for a sensor pair, or a "
                                     "polynomial in one channel with optional terms");
  cmd->add_option("DATA", a->data, "tidy CSV ('-' = stdin)")->required();
  cmd->add_option("--model", a->request.model,
                  "guo2006 (Eq. (2); the default where the runs have both channels of --pair), "
                  "poly (the default otherwise), px4, ardupilot or auto (docs/data-format.md)");
  auto* fit_pair = cmd->add_option("--pair", a->pair, "guo2006: sensor pair Ti,Tj")->capture_default_str();
  cmd->add_option("--runs", a->runs, "runs to fit on (default: all)")->delimiter(',');
  cmd->add_option("-o,--output", a->out, "write the coefficients JSON here ('-' = stdout)");
  auto* fit_method = cmd->add_option("--method", a->method,
                                     "guo2006: joint (all nine A in one least squares) or "
                                     "two_stage (the paper's)")
                         ->capture_default_str();
  cmd->add_option("--b0-window", a->request.b0_window_s, "B0 = mean bias over this many seconds after power-on")
      ->capture_default_str();
  cmd->add_option("--average", a->average_s, "fit on means over this many seconds (0: the samples as given)")
      ->capture_default_str();
  cmd->add_option("--until", a->until_s,
                  "fit on each run's samples before this time (s after its first sample); "
                  "the model's states run from the power-on as in use (a cycle's first part)");
  cmd->add_flag("--json", a->json, "print the coefficients JSON instead of the summary");
  cmd->add_option("--channel", a->request.channel, "poly, px4, ardupilot, auto: the temperature channel (default T1)");
  cmd->add_option("--order", a->request.order, "poly: the polynomial's order, 1 to 5 (default 3)");
  cmd->add_option("--terms", a->request.terms,
                  "poly: extra terms rate,hysteresis,lag,gradient (gradient:T2 for one "
                  "channel) or products such as 'T1*(T2-T1)', '(T2-T1)^2', 'rate(T2-T1)'; "
                  "auto: the library it searches")
      ->delimiter(',');
  cmd->add_option("--beyond-range", a->request.beyond_range,
                  "poly: hold (the polynomial held at the fitted range's edge, "
                  "the default) or extrapolate");
  cmd->add_option("--offset", a->request.offset,
                  "poly, auto: fitted (a constant bias) or power_on (bias minus B0, the "
                  "polynomial referred to the power-on temperature); default poly: fitted, "
                  "auto: chosen");
  cmd->add_option("--reference", a->request.reference_C,
                  "poly, px4, auto: T_ref in °C (default the middle of the fitted "
                  "span; ardupilot: 35)");
  return {cmd, [a, fit_pair, fit_method] {
            a->pair_given = fit_pair->count() > 0;
            a->method_given = fit_method->count() > 0;
            return RunFit(*a);
          }};
}

Verb RegisterPairs(CLI::App& app) {
  auto a = std::make_shared<PairsArgs>();
  CLI::App* cmd = app.add_subcommand("pairs", "Table 1: SSE per run and SSE_ave for M1..M6");
  cmd->add_option("DATA", a->data, "tidy CSV ('-' = stdin)")->required();
  cmd->add_option("--runs", a->runs, "runs to use (default: all)")->delimiter(',');
  cmd->add_flag("--all", a->all, "every ordered pair of the temperature channels, not only M1..M6");
  cmd->add_option("--average", a->average_s, "work on means over this many seconds (the paper: 60)")
      ->capture_default_str();
  cmd->add_option("--b0-window", a->b0_window_s, "B0 window (s)")->capture_default_str();
  cmd->add_flag("--json", a->json, "machine-readable output (keys: docs/data-format.md)");
  return {cmd, [a] { return RunPairs(*a); }};
}

Verb RegisterAllan(CLI::App& app) {
  auto a = std::make_shared<AllanArgs>();
  CLI::App* cmd = app.add_subcommand("allan", "Allan deviation with ARW, bias instability and RRW read-offs");
  cmd->add_option("DATA", a->data, "tidy CSV ('-' = stdin)")->required();
  cmd->add_option("--run", a->run, "one run (default: every run)");
  cmd->add_option("--column", a->column, "rate column to analyse (°/h), e.g. your own compensated bias")
      ->capture_default_str();
  cmd->add_flag("--json", a->json, "machine-readable output (keys: docs/data-format.md)");
  cmd->add_option("--plot", a->plot, "directory for figures: allan_<run>.png with the fitted noise lines");
  return {cmd, [a] { return RunAllan(*a); }};
}

}  // namespace rlg::cli
