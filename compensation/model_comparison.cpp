#include "compensation/model_comparison.h"

#include <algorithm>
#include <cmath>
#include <fmt/format.h>
#include <fmt/ranges.h>
#include <functional>
#include <iterator>
#include <limits>
#include <numeric>

#include "compensation/model_compensator.h"
#include "model/allan.h"
#include "model/coefficients_json.h"
#include "model/guo2006_regressors.h"
#include "model/linear_fit.h"
#include "model/model_selection.h"
#include "model/pairs.h"
#include "model/poly_fit.h"
#include "sim/errors.h"

namespace rlg::compensation {

bool ComparisonOptions::IsValid(std::string* error) const {
  std::string why;
  if (!(train_fraction > 0.0 && train_fraction < 1.0)) why = fmt::format("train_fraction must lie in (0, 1) (got {:g})", train_fraction);
  else if (cut_s && !(*cut_s > 0.0)) why = fmt::format("the cut must lie after the runs' first samples (got {:g} s)", *cut_s);
  else if (cut_s && !fit_runs.empty()) why = "a cut in time and --fit-runs both choose the training data: give one";
  else if (folds < 2) why = fmt::format("folds must be at least 2 (got {})", folds);
  else if (min_runs_as_folds < 2) why = fmt::format("min_runs_as_folds must be at least 2 (got {})", min_runs_as_folds);
  else if (!(min_gain >= 0.0 && min_gain < 1.0)) why = fmt::format("min_gain must lie in [0, 1) (got {:g})", min_gain);
  else if (!(b0_window_s > 0.0)) why = fmt::format("the B0 window must be positive (got {:g} s)", b0_window_s);
  else if (!(averaging_s > 0.0)) why = fmt::format("the averaging time must be positive (got {:g} s)", averaging_s);
  if (error) *error = why;
  return why.empty();
}

namespace {

std::string Times(const Segment& s) { return fmt::format("t = {:g}-{:g} s", s.t_from_s, s.t_to_s); }

nlohmann::json SegmentJson(const Segment& s) {
  return {{"run", s.run}, {"t_from_s", s.t_from_s}, {"t_to_s", s.t_to_s}, {"samples", s.count}};
}

nlohmann::json Finite(double x) { return std::isfinite(x) ? nlohmann::json(x) : nlohmann::json(nullptr); }

/// One model to compare: how to fit it on the training runs and how to score it inside them.
struct Candidate {
  std::string label;
  nlohmann::json options;
  std::function<model::FittedModel(const std::vector<const sim::Run*>&)> fit;
  std::function<double(const std::vector<const sim::Run*>&, const std::vector<model::RowMask>&, const model::FittedModel&)> cv;
};

model::PolyFitOptions PolyOptions(const ComparisonOptions& o, int order, const std::vector<std::string>& terms) {
  model::PolyFitOptions p;
  p.channel = o.channel;
  p.order = order;
  p.terms = terms;
  p.b0_window_s = o.b0_window_s;
  return p;
}

Candidate PolyCandidate(const std::string& label, nlohmann::json options, model::PolyFitOptions p) {
  Candidate c;
  c.label = label;
  c.options = std::move(options);
  c.fit = [p](const std::vector<const sim::Run*>& runs) { return model::FittedModel(model::FitPoly(runs, p)); };
  c.cv = [p](const std::vector<const sim::Run*>& runs, const std::vector<model::RowMask>& folds, const model::FittedModel&) {
    return model::PolyCvRms(runs, folds, p);
  };
  return c;
}

std::vector<Candidate> Candidates(const ComparisonOptions& o, const std::vector<const sim::Run*>& train) {
  std::vector<Candidate> out;
  bool has_pair = true;
  for (const sim::Run* r : train) has_pair = has_pair && r->Has(o.pair[0]) && r->Has(o.pair[1]);
  if (has_pair) {
    Candidate c;
    c.label = fmt::format("guo2006 ({}, {})", o.pair[0], o.pair[1]);
    c.options = {{"model", "guo2006"}, {"pair", {o.pair[0], o.pair[1]}}};
    model::FitOptions f;
    f.pair = o.pair;
    f.b0_window_s = o.b0_window_s;
    c.fit = [f](const std::vector<const sim::Run*>& runs) { return model::FittedModel(model::FitGuo2006(runs, f)); };
    c.cv = [f](const std::vector<const sim::Run*>& runs, const std::vector<model::RowMask>& folds, const model::FittedModel&) {
      const model::Guo2006Regressors g(f.pair, f.b0_window_s);
      model::LinearFitOptions lo;
      lo.errors = false;
      return model::BlockedCvRms(runs, folds, [&](const model::RowMask& mask) {
        return model::LinearCompensator(g, model::FitLinear(model::BuildDesign(runs, g, mask), lo).beta);
      });
    };
    out.push_back(c);
  }
  for (const model::PolyPreset kind : {model::PolyPreset::kPx4, model::PolyPreset::kArduPilot}) {
    const std::string preset = model::PolyPresetName(kind);
    model::PolyFitOptions p = model::PresetOptions(kind);
    p.channel = o.channel;
    p.b0_window_s = o.b0_window_s;
    out.push_back(PolyCandidate(preset, {{"model", preset}, {"channel", o.channel}}, p));
  }
  for (int order = 1; order <= 5; ++order) {
    out.push_back(PolyCandidate(fmt::format("poly order {}", order),
                                {{"model", "poly"}, {"channel", o.channel}, {"order", order}, {"offset", "fitted"}},
                                PolyOptions(o, order, {})));
  }
  std::vector<std::string> terms = {"rate", "hysteresis", "lag"};
  bool other_channel = false;
  for (const auto& ch : model::TemperatureChannels(*train.front())) {
    bool everywhere = ch != o.channel;
    for (const sim::Run* r : train) everywhere = everywhere && r->Has(ch);
    other_channel = other_channel || everywhere;
  }
  if (other_channel) terms.push_back("gradient");
  for (const auto& t : terms) {
    out.push_back(PolyCandidate(fmt::format("poly order 3 + {}", t),
                                {{"model", "poly"}, {"channel", o.channel}, {"order", 3}, {"offset", "fitted"}, {"terms", {t}}},
                                PolyOptions(o, 3, {t})));
  }
  Candidate a;
  a.label = model::PolyPresetName(model::PolyPreset::kAuto);
  a.options = {{"model", a.label}, {"channel", o.channel}};
  model::AutoOptions ao;
  ao.channel = o.channel;
  ao.b0_window_s = o.b0_window_s;
  ao.folds = o.folds;
  ao.min_runs_as_folds = o.min_runs_as_folds;
  ao.min_gain = o.min_gain;
  a.fit = [ao](const std::vector<const sim::Run*>& runs) { return model::FittedModel(model::FitAuto(runs, ao)); };
  a.cv = [ao](const std::vector<const sim::Run*>& runs, const std::vector<model::RowMask>& folds, const model::FittedModel& m) {
    return model::PolyCvRms(runs, folds, model::OptionsOf(std::get<model::PolyModel>(m), ao));
  };
  out.push_back(a);
  return out;
}

/// Linear coefficients plus the profiled time constants and widths, and the offset: a fitted
/// constant is a coefficient; a power-on offset's B0, measured on each run, counts as one too
/// (as auto counts it, model/model_selection.h).
int Parameters(const model::FittedModel& m) {
  int k = static_cast<int>(model::ModelCoefficients(m).size()) + (model::ModelB0Window(m) > 0.0 ? 1 : 0);
  if (const auto* p = std::get_if<model::PolyModel>(&m)) {
    for (const auto& t : p->spec.terms) k += t.kind == model::TermKind::kHysteresis || t.kind == model::TermKind::kLag ? 1 : 0;
  }
  return k;
}

/// AIC_eff of the header from the compensated training runs.
double AicEff(const std::vector<std::vector<double>>& residuals, int k) {
  double rss = 0.0, c0 = 0.0, c1 = 0.0;
  size_t n = 0;
  for (const auto& r : residuals) {
    const double mean = std::accumulate(r.begin(), r.end(), 0.0) / static_cast<double>(std::max<size_t>(r.size(), 1));
    for (size_t i = 0; i < r.size(); ++i) {
      rss += r[i] * r[i];
      c0 += (r[i] - mean) * (r[i] - mean);
      if (i > 0) c1 += (r[i] - mean) * (r[i - 1] - mean);
    }
    n += r.size();
  }
  const double rho = std::clamp(c0 > 0.0 ? c1 / c0 : 0.0, 0.0, 0.999);
  const double n_eff = static_cast<double>(n) * (1.0 - rho) / (1.0 + rho);
  return n_eff * std::log(rss / static_cast<double>(n)) + 2.0 * k;
}

/// Each held-out stretch: a run and its first held-out sample.
using Heldout = std::vector<std::pair<const sim::Run*, size_t>>;

/// --fit-runs: those runs fitted whole, the others scored whole. Returns the training runs.
std::vector<sim::Run> SplitByRuns(const sim::Trace& trace, const ComparisonOptions& o, Comparison& c, Heldout& heldout) {
  std::vector<sim::Run> train_runs;
  const auto chosen = trace.Select(o.fit_runs);
  for (const sim::Run* r : chosen) {
    train_runs.push_back(*r);
    c.training.push_back({r->id, 0, r->size(), r->t_s.front(), r->t_s.back()});
  }
  for (const auto& r : trace.runs) {
    if (std::find(chosen.begin(), chosen.end(), &r) != chosen.end()) continue;
    heldout.emplace_back(&r, 0);
    c.heldout.push_back({r.id, 0, r.size(), r.t_s.front(), r.t_s.back()});
  }
  if (heldout.empty()) {
    throw InputError(fmt::format("{}: --fit-runs names every run ({}): none is left to score; name fewer, or none to "
                                 "cut each run in time", c.data, fmt::join(o.fit_runs, ",")));
  }
  std::vector<std::string> train_ids, held_ids;
  for (const auto& s : c.training) train_ids.push_back(s.run);
  for (const auto& s : c.heldout) held_ids.push_back(s.run);
  c.split = fmt::format("fitted on run{} {}; scored on run{} {} (whole runs, compensated from power-on)",
                        train_ids.size() == 1 ? "" : "s", fmt::join(train_ids, ", "), held_ids.size() == 1 ? "" : "s",
                        fmt::join(held_ids, ", "));
  return train_runs;
}

/// Each run cut in time (at cut_s, or at train_fraction of its duration): its first part fitted,
/// the rest scored. Returns the training runs (copies of the first parts).
std::vector<sim::Run> SplitInTime(const sim::Trace& trace, const ComparisonOptions& o, Comparison& c, Heldout& heldout) {
  std::vector<sim::Run> train_runs;
  std::vector<std::string> parts;
  for (const auto& r : trace.runs) {
    if (r.size() < 4) throw InputError(fmt::format("{} has {} samples: too few to cut in time", r.Where(), r.size()));
    const size_t first = sim::FirstSampleAt(r, o.cut_s ? *o.cut_s : o.train_fraction * (r.t_s.back() - r.t_s.front()));
    if (first < 2 || first + 2 > r.size()) {
      throw InputError(o.cut_s ? fmt::format("{} lasts {:g} s: the cut at {:g} s leaves fewer than two samples on a "
                                             "side", r.Where(), r.t_s.back() - r.t_s.front(), *o.cut_s)
                               : fmt::format("{} is too short to cut in time", r.Where()));
    }
    train_runs.push_back(sim::Head(r, first));
    c.training.push_back({r.id, 0, first, r.t_s.front(), r.t_s[first - 1]});
    heldout.emplace_back(&r, first);
    c.heldout.push_back({r.id, first, r.size() - first, r.t_s[first], r.t_s.back()});
    parts.push_back(fmt::format("fitted on {}, scored on {}", Times(c.training.back()), Times(c.heldout.back())));
  }
  if (trace.runs.size() == 1) {
    c.split = fmt::format("one run, held out in time: {}", parts.front());
  } else {
    std::vector<std::string> each;
    for (size_t i = 0; i < parts.size(); ++i) each.push_back(fmt::format("run '{}': {}", trace.runs[i].id, parts[i]));
    c.split = o.cut_s ? fmt::format("each run cut in time at {:g} s (before it fitted, the rest scored): {}", *o.cut_s,
                                    fmt::join(each, "; "))
                      : fmt::format("each run held out in time (the first {:g} % of its duration fitted, the rest scored): {}",
                                    100.0 * o.train_fraction, fmt::join(each, "; "));
  }
  return train_runs;
}

/// InputError unless each held-out stretch holds two 100 s blocks (the 100 s stability) and the
/// bias column and the channel.
void CheckHeldout(const Comparison& c, const Heldout& heldout, const ComparisonOptions& o) {
  for (size_t i = 0; i < heldout.size(); ++i) {
    const sim::Run& r = *heldout[i].first;
    const double dt = model::SamplePeriod(r.t_s);
    const size_t block = std::max<size_t>(1, static_cast<size_t>(std::lround(100.0 / dt)));
    if (c.heldout[i].count < 2 * block) {
      throw InputError(fmt::format("{}: the held-out part ({}) has {} samples, fewer than two 100 s blocks ({} samples "
                                   "each at {:g} s): too short to score",
                                   r.Where(), Times(c.heldout[i]), c.heldout[i].count, block, dt));
    }
    r.Column(o.bias_column);
    r.Column(o.channel);
  }
}

/// The held-out scores of a fitted model: compensated from each run's power-on, scored on its
/// held-out stretch.
void ScoreHeldout(ComparedModel& m, const Heldout& heldout, const ComparisonOptions& o) {
  const model::FittedModel& f = *m.fitted;
  double sum2 = 0.0, sum = 0.0, stab = 0.0, stab100 = 0.0;
  size_t n = 0;
  EvaluationOptions eo;
  eo.averaging_s = o.averaging_s;
  eo.bias_column = o.bias_column;
  eo.trend_channel = model::ModelChannels(f).front();
  if (model::ModelB0Window(f) > 0.0) eo.b0_window_s = model::ModelB0Window(f);
  for (const auto& [run, first] : heldout) {
    const std::vector<double> out = CompensateRun(f, *run, o.bias_column);
    const std::vector<double> part(out.begin() + static_cast<std::ptrdiff_t>(first), out.end());
    const sim::Run tail = sim::Tail(*run, first);
    m.heldout.push_back(EvaluateCompensated(tail, part, eo));
    const auto& T = tail.Column(eo.trend_channel);
    for (size_t k = 0; k < part.size(); ++k) {
      sum2 += part[k] * part[k];
      sum += part[k];
      m.heldout_T.push_back(T[k]);
      m.heldout_residual.push_back(part[k]);
    }
    n += part.size();
    stab += m.heldout.back().stability_after.sigma * m.heldout.back().stability_after.sigma;
    stab100 += m.heldout.back().stability_100s_after.sigma * m.heldout.back().stability_100s_after.sigma;
  }
  m.heldout_rms_dph = std::sqrt(sum2 / static_cast<double>(n));
  m.heldout_bias_dph = sum / static_cast<double>(n);
  m.heldout_stability_dph = std::sqrt(stab / static_cast<double>(heldout.size()));
  m.heldout_stability_100s_dph = std::sqrt(stab100 / static_cast<double>(heldout.size()));
}

/// One candidate fitted on the training runs and scored: cross-validated inside them, on them
/// (parameters, RMS, AIC) and held out; a NumericalError of its fit makes it not applicable.
ComparedModel FitAndScore(const Candidate& cand, const std::vector<const sim::Run*>& train,
                          const std::vector<model::RowMask>& folds, const Heldout& heldout,
                          const ComparisonOptions& o) {
  ComparedModel m;
  m.label = cand.label;
  m.options = cand.options;
  try {
    const model::FittedModel fitted = cand.fit(train);
    m.cv_rms_dph = cand.cv(train, folds, fitted);
    m.fitted = fitted;
  } catch (const NumericalError& e) {
    m.not_applicable = e.what();
    return m;
  }
  const model::FittedModel& f = *m.fitted;
  m.parameters = Parameters(f);
  m.train_rms_dph = model::ModelResidualRms(f);
  std::vector<std::vector<double>> residuals;
  for (const sim::Run* r : train) residuals.push_back(CompensateRun(f, *r, o.bias_column));
  m.aic_eff = AicEff(residuals, m.parameters);
  if (const auto* p = std::get_if<model::PolyModel>(&f); p && p->preset == model::PolyPreset::kAuto) {
    nlohmann::json form = {{"order", p->spec.order}, {"offset", model::OffsetName(p->spec.offset)}};
    form["terms"] = nlohmann::json::array();
    for (const auto& t : p->spec.terms) form["terms"].push_back(t.Spelling());
    m.options["selected_form"] = form;
    if (p->selection) m.selection = *p->selection;
  }
  ScoreHeldout(m, heldout, o);
  return m;
}

/// Ranks the models by the training score (those that do not apply last, in their order) and
/// selects one: the fewest parameters within min_gain of the best; says why, and how the
/// held-out data support it.
void SelectModel(Comparison& c, const ComparisonOptions& o) {
  std::stable_sort(c.models.begin(), c.models.end(), [](const ComparedModel& a, const ComparedModel& b) {
    const double sa = a.fitted ? a.cv_rms_dph : std::numeric_limits<double>::infinity();
    const double sb = b.fitted ? b.cv_rms_dph : std::numeric_limits<double>::infinity();
    return sa < sb;
  });
  if (!c.models.empty() && c.models.front().fitted && std::isfinite(c.models.front().cv_rms_dph)) {
    const double best = c.models.front().cv_rms_dph;
    int chosen = 0, within = 0;
    for (size_t i = 0; i < c.models.size(); ++i) {
      const ComparedModel& m = c.models[i];
      if (!m.fitted || !(m.cv_rms_dph * m.cv_rms_dph <= (1.0 + o.min_gain) * best * best)) continue;
      ++within;
      if (m.parameters < c.models[static_cast<size_t>(chosen)].parameters) chosen = static_cast<int>(i);
    }
    c.selected = chosen;
    const ComparedModel& s = c.models[static_cast<size_t>(chosen)];
    c.why = chosen == 0
                ? fmt::format("the lowest cross-validation RMS inside the training data ({:.4g} °/h){}", best,
                              within > 1 ? fmt::format(", and no model within {:g} % of it (mean square) has fewer "
                                                       "parameters than its {}", 100.0 * o.min_gain, s.parameters)
                                         : "")
                : fmt::format("the fewest parameters ({}) of the {} models whose cross-validation RMS inside the training "
                              "data lies within {:g} % (mean square) of the lowest ({:.4g} °/h, {}); its own: {:.4g} °/h",
                              s.parameters, within, 100.0 * o.min_gain, best, c.models.front().label, s.cv_rms_dph);
    c.heldout_over_cv = s.heldout_rms_dph / s.cv_rms_dph;
    c.support = c.heldout_over_cv <= kMaxHeldoutOverCv
                    ? fmt::format("held out, the selected model's RMS is {:.2f} times its cross-validation RMS inside "
                                  "the training data: the training data predicted the held-out data",
                                  c.heldout_over_cv)
                    : fmt::format("held out, the selected model's RMS is {:.2f} times its cross-validation RMS inside "
                                  "the training data: the training data do not predict the held-out data (a "
                                  "temperature range, a heating or cooling branch or a time they do not cover); every "
                                  "model's held-out numbers are what this split supports, not its accuracy in use",
                                  c.heldout_over_cv);
  }
}

}  // namespace

Comparison CompareModels(const sim::Trace& trace, const ComparisonOptions& o) {
  std::string invalid;
  if (!o.IsValid(&invalid)) throw InputError("compare: " + invalid);
  if (trace.runs.empty()) throw InputError(fmt::format("{}: no runs", trace.source));
  Comparison c;
  c.data = trace.source.empty() ? "the data" : trace.source;

  // Training runs (copies of the first parts when cut in time) and held-out stretches.
  Heldout heldout;
  const std::vector<sim::Run> train_runs =
      o.fit_runs.empty() ? SplitInTime(trace, o, c, heldout) : SplitByRuns(trace, o, c, heldout);
  CheckHeldout(c, heldout, o);
  std::vector<const sim::Run*> train;
  for (const auto& r : train_runs) train.push_back(&r);
  const std::vector<model::RowMask> folds = model::SelectionFolds(train, o.folds, o.min_runs_as_folds);

  const auto candidates = Candidates(o, train);
  for (size_t ci = 0; ci < candidates.size(); ++ci) {
    const Candidate& cand = candidates[ci];
    if (o.progress) o.progress(fmt::format("fitting {} ({} of {})", cand.label, ci + 1, candidates.size()));
    c.models.push_back(FitAndScore(cand, train, folds, heldout, o));
  }

  SelectModel(c, o);
  return c;
}

nlohmann::json ComparisonJson(const Comparison& c) {
  nlohmann::json j;
  j["data"] = c.data;
  j["split"] = c.split;
  j["training"] = nlohmann::json::array();
  for (const auto& s : c.training) j["training"].push_back(SegmentJson(s));
  j["heldout"] = nlohmann::json::array();
  for (const auto& s : c.heldout) j["heldout"].push_back(SegmentJson(s));
  j["models"] = nlohmann::json::array();
  for (const auto& m : c.models) {
    nlohmann::json e = m.options;
    e["label"] = m.label;
    if (!m.fitted) {
      e["not_applicable"] = m.not_applicable;
      j["models"].push_back(e);
      continue;
    }
    e["parameters"] = m.parameters;
    e["train_rms_dph"] = m.train_rms_dph;
    e["cv_rms_dph"] = Finite(m.cv_rms_dph);
    e["aic_eff"] = Finite(m.aic_eff);
    e["heldout_rms_dph"] = m.heldout_rms_dph;
    e["heldout_bias_dph"] = m.heldout_bias_dph;
    e["heldout_stability_dph"] = m.heldout_stability_dph;
    e["heldout_stability_100s_dph"] = m.heldout_stability_100s_dph;
    e["heldout"] = nlohmann::json::array();
    for (const auto& h : m.heldout) e["heldout"].push_back(EvaluationJson(h));
    e["coefficients_file"] = model::ModelToJson(*m.fitted);
    if (m.selection) {
      auto steps = [](const std::vector<model::SelectionStep>& list) {
        nlohmann::json out = nlohmann::json::array();
        for (const auto& st : list) {
          nlohmann::json x = {{"model", st.candidate}, {"cv_rms_dph", Finite(st.cv_rms_dph)}, {"parameters", st.parameters}};
          if (!st.note.empty()) x["move"] = st.note;
          out.push_back(x);
        }
        return out;
      };
      e["selection"] = {{"rule", m.selection->rule}, {"folds", m.selection->folds}, {"path", steps(m.selection->steps)},
                        {"visited", steps(m.selection->visited)}};
    }
    j["models"].push_back(e);
  }
  if (c.selected >= 0) {
    const ComparedModel& s = c.models[static_cast<size_t>(c.selected)];
    nlohmann::json sel = s.options;
    sel["label"] = s.label;
    sel["why"] = c.why;
    sel["heldout_over_cv"] = Finite(c.heldout_over_cv);
    sel["supported"] = c.heldout_over_cv <= kMaxHeldoutOverCv;
    sel["support"] = c.support;
    j["selected"] = sel;
  } else {
    j["selected"] = nullptr;
  }
  return j;
}

std::string ComparisonText(const Comparison& c) {
  fmt::memory_buffer out;
  auto line = std::back_inserter(out);
  fmt::format_to(line, "Models compared on {}: {}\n", c.data, c.split);
  fmt::format_to(line, "Ranked by cross-validation RMS inside the training data (contiguous pieces of each training run), "
                       "the selection's score (auto's is optimistic: it chose its form on the same pieces); the held-out "
                       "columns are reported, never used to select.\n");
  fmt::format_to(line, "{:<4} {:<26} {:<34} {:>6} {:>10} {:>10} {:>11} {:>12} {:>11} {:>11} {:>10}\n", "rank", "model",
                 "form and terms", "params", "train RMS", "CV RMS", "held RMS", "held bias", "held stab", "held st100",
                 "AIC_eff");
  int rank = 0;
  for (const auto& m : c.models) {
    if (!m.fitted) continue;
    std::string form = "Eq. (2)";
    if (const auto* p = std::get_if<model::PolyModel>(&*m.fitted)) {
      form = fmt::format("order {}, {}", p->spec.order, model::OffsetName(p->spec.offset));
      for (const auto& t : p->spec.terms) form += " + " + (t.kind == model::TermKind::kGradient ? "grad " + t.channel : t.Spelling());
    }
    fmt::format_to(line, "{:<4} {:<26} {:<34} {:>6} {:>10.4f} {:>10.4f} {:>11.4f} {:>+12.4f} {:>11.4f} {:>11.4f} {:>10.1f}{}\n",
                   ++rank, m.label, form, m.parameters, m.train_rms_dph, m.cv_rms_dph, m.heldout_rms_dph,
                   m.heldout_bias_dph, m.heldout_stability_dph, m.heldout_stability_100s_dph, m.aic_eff,
                   static_cast<int>(&m - c.models.data()) == c.selected ? "  <- selected" : "");
  }
  fmt::format_to(line, "  (°/h; held stab: 1 sigma of consecutive means at the first stability time of Table 2, held "
                       "st100 at 100 s, as computed per held-out stretch, RMS over stretches)\n");
  for (const auto& m : c.models) {
    if (!m.fitted) fmt::format_to(line, "not applicable: {}: {}\n", m.label, m.not_applicable);
  }
  if (c.selected >= 0) {
    const ComparedModel& s = c.models[static_cast<size_t>(c.selected)];
    fmt::format_to(line, "selected: {} ({}): {}\n", s.label, model::ModelTitle(*s.fitted), c.why);
    fmt::format_to(line, "{}{}\n", c.heldout_over_cv <= kMaxHeldoutOverCv ? "" : "warning: ", c.support);
  }
  for (const auto& m : c.models) {
    if (!m.fitted || !m.selection) continue;
    fmt::format_to(line, "{}'s search ({} models scored; CV RMS inside the training data, {} folds):\n", m.label,
                   m.selection->visited.size(), m.selection->folds);
    for (const auto& st : m.selection->steps) {
      fmt::format_to(line, "  {:<44} {:>9} °/h  {:>3} params  {}\n", st.note.rfind("selected", 0) == 0 ? "selected" : st.note,
                     std::isfinite(st.cv_rms_dph) ? fmt::format("{:.5f}", st.cv_rms_dph) : "-", st.parameters, st.candidate);
    }
  }
  fmt::format_to(line, "Parameters (± 95 % half-width, Student's t; the errors of guo2006 as `fit` reports them, the "
                       "others cluster-robust, model/linear_fit.h):\n");
  for (const auto& m : c.models) {
    if (!m.fitted) continue;
    std::vector<std::string> items;
    if (const auto* p = std::get_if<model::PolyModel>(&*m.fitted)) {
      for (const auto& t : p->spec.terms)
        if (t.kind != model::TermKind::kGradient) items.push_back(t.Describe());
    }
    for (const auto& k : model::ModelCoefficients(*m.fitted)) {
      const double hw = k.dof > 0.0 ? model::StudentQuantile(0.95, k.dof) * k.standard_error : NAN;
      items.push_back(std::isfinite(hw) ? fmt::format("{} {:+.4g} ± {:.2g}", k.name, k.value, hw)
                                        : fmt::format("{} {:+.4g}", k.name, k.value));
    }
    fmt::format_to(line, "  {}: {}\n", m.label, fmt::join(items, ", "));
  }
  return fmt::to_string(out);
}

}  // namespace rlg::compensation
