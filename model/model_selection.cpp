#include "model/model_selection.h"

#include <algorithm>
#include <cmath>
#include <fmt/format.h>
#include <limits>

#include "model/pairs.h"
#include "sim/errors.h"

namespace rlg::model {

std::vector<RowMask> BlockFolds(const std::vector<const sim::Run*>& runs, int folds) {
  if (folds < 2) throw InputError(fmt::format("cross-validation needs at least 2 folds (got {})", folds));
  std::vector<RowMask> out(static_cast<size_t>(folds));
  for (const sim::Run* run : runs) {
    const size_t n = run->size();
    if (n < 2 * static_cast<size_t>(folds)) {
      throw InputError(fmt::format("{} has {} samples: too few to cut into {} pieces of 2 or more for "
                                   "cross-validation", run->Where(), n, folds));
    }
    for (int k = 0; k < folds; ++k) {
      std::vector<char> mask(n, 1);
      const size_t begin = n * static_cast<size_t>(k) / static_cast<size_t>(folds);
      const size_t end = n * static_cast<size_t>(k + 1) / static_cast<size_t>(folds);
      std::fill(mask.begin() + static_cast<std::ptrdiff_t>(begin), mask.begin() + static_cast<std::ptrdiff_t>(end), 0);
      out[static_cast<size_t>(k)].push_back(std::move(mask));
    }
  }
  return out;
}

CvScore BlockedCv(const std::vector<const sim::Run*>& runs, const std::vector<RowMask>& folds, const FoldFit& fit,
                  const std::string& bias_column) {
  CvScore score;
  double sum = 0.0;
  size_t count = 0;
  for (const RowMask& mask : folds) {
    LinearCompensator comp = fit(mask);
    const std::vector<std::string>& channels = comp.regressors().channels();
    std::vector<double> T(channels.size());
    double fold_sum = 0.0;
    size_t fold_count = 0;
    for (size_t r = 0; r < runs.size(); ++r) {
      const sim::Run& run = *runs[r];
      std::vector<const std::vector<double>*> columns;
      for (const auto& ch : channels) columns.push_back(&run.Column(ch));
      const std::vector<double>& bias = run.Column(bias_column);
      comp.Reset();
      for (size_t k = 0; k < run.size(); ++k) {
        for (size_t c = 0; c < channels.size(); ++c) T[c] = (*columns[c])[k];
        const double out = comp.Update(run.t_s[k], T.data(), bias[k]);
        if (mask[r][k] || comp.regressors().OutsideFittedRange()) continue;
        fold_sum += out * out;
        ++fold_count;
      }
    }
    score.fold_ms.push_back(fold_count > 0 ? fold_sum / static_cast<double>(fold_count) : 0.0);
    sum += fold_sum;
    count += fold_count;
  }
  score.rms = std::sqrt(sum / static_cast<double>(std::max<size_t>(count, 1)));
  return score;
}

double BlockedCvRms(const std::vector<const sim::Run*>& runs, const std::vector<RowMask>& folds, const FoldFit& fit,
                    const std::string& bias_column) {
  return BlockedCv(runs, folds, fit, bias_column).rms;
}

CvScore PolyCv(const std::vector<const sim::Run*>& runs, const std::vector<RowMask>& folds, PolyFitOptions options) {
  options.linear.errors = false;
  return BlockedCv(runs, folds, [&](const RowMask& mask) {
    const PolyModel m = FitPoly(runs, options, mask);
    return LinearCompensator(PolyRegressors(m.spec), m.Beta());
  });
}

bool Beats(const CvScore& b, const CvScore& a, double min_gain) {
  if (!(b.rms * b.rms <= (1.0 - min_gain) * a.rms * a.rms)) return false;
  size_t lower = 0;
  const size_t folds = std::min(b.fold_ms.size(), a.fold_ms.size());
  for (size_t k = 0; k < folds; ++k) lower += b.fold_ms[k] < a.fold_ms[k] ? 1 : 0;
  return 4 * lower >= 3 * folds;
}

int SmallestUnbeatenOrder(const std::vector<CvScore>& by_order, double min_gain) {
  const int orders = static_cast<int>(by_order.size());
  for (int p = 1; p <= orders; ++p) {
    const CvScore& s = by_order[static_cast<size_t>(p - 1)];
    if (!std::isfinite(s.rms)) continue;
    bool beaten = false;
    for (int q = p + 1; q <= orders; ++q) beaten = beaten || Beats(by_order[static_cast<size_t>(q - 1)], s, min_gain);
    if (!beaten) return p;
  }
  return 0;
}

double PolyCvRms(const std::vector<const sim::Run*>& runs, const std::vector<RowMask>& folds, PolyFitOptions options) {
  return PolyCv(runs, folds, std::move(options)).rms;
}

bool AutoOptions::IsValid(std::string* error) const {
  std::string why;
  if (folds < 2) why = fmt::format("folds must be at least 2 (got {})", folds);
  else if (!(min_gain >= 0.0 && min_gain < 1.0)) why = fmt::format("min_gain must lie in [0, 1) (got {:g})", min_gain);
  else {
    PolyFitOptions o;
    o.channel = channel;
    o.reference_C = reference_C;
    o.b0_window_s = b0_window_s;
    o.rate_tau_s = rate_tau_s;
    o.terms = candidate_terms;
    o.linear = linear;
    o.profile = profile;
    o.IsValid(&why);
  }
  if (error) *error = why;
  return why.empty();
}

std::string AutoRule(const AutoOptions& o) {
  return fmt::format("forward selection on the RMS of the compensated bias over {} contiguous held-out pieces of each "
                     "training run (samples inside the fold's fitted range); a model beats another when its mean "
                     "square is {:g} % lower overall and lower in three quarters of the folds. For each offset rule: the smallest order "
                     "no higher order beats; then the best term while it beats the model without it; then the order "
                     "again. Then the offset whose model has the fewest parameters and is beaten by no other",
                     o.folds, 100.0 * o.min_gain);
}

namespace {

std::string Describe(OffsetRule offset, int order, const std::vector<std::string>& terms) {
  std::string s = fmt::format("order {}, {}", order, OffsetName(offset));
  for (const auto& t : terms) s += " + " + t;
  return s;
}

}  // namespace

PolyFitOptions OptionsOf(const PolyModel& m, const AutoOptions& a) {
  PolyFitOptions o;
  o.channel = m.spec.channel;
  o.order = m.spec.order;
  o.offset = m.spec.offset;
  o.reference_C = a.reference_C;
  o.b0_window_s = a.b0_window_s;
  o.rate_tau_s = a.rate_tau_s;
  o.linear = a.linear;
  o.profile = a.profile;
  for (const auto& t : m.spec.terms) o.terms.push_back(t.kind == TermKind::kGradient ? "gradient:" + t.channel : TermKindName(t.kind));
  return o;
}

PolyModel FitAuto(const std::vector<const sim::Run*>& runs, const AutoOptions& a) {
  std::string invalid;
  if (!a.IsValid(&invalid)) throw InputError("auto: " + invalid);
  if (runs.empty()) throw InputError("auto: no runs to fit");
  const std::vector<RowMask> folds = BlockFolds(runs, a.folds);
  SelectionRecord record;
  record.rule = AutoRule(a);
  record.folds = a.folds;

  PolyFitOptions base;
  base.channel = a.channel;
  base.reference_C = a.reference_C;
  base.b0_window_s = a.b0_window_s;
  base.rate_tau_s = a.rate_tau_s;
  base.linear = a.linear;
  base.profile = a.profile;
  base.preset = "auto";

  std::vector<OffsetRule> offsets;
  if (a.offset) {
    offsets.push_back(*a.offset);
  } else {
    offsets.push_back(OffsetRule::kFitted);
    bool spans = true;
    for (const sim::Run* run : runs) spans = spans && run->size() > 0 && run->t_s.back() >= run->t_s.front() + a.b0_window_s;
    if (spans) offsets.push_back(OffsetRule::kPowerOn);
  }
  std::vector<std::string> candidates = a.candidate_terms;
  if (candidates.empty()) {
    candidates = {"rate", "hysteresis", "lag"};
    for (const auto& ch : TemperatureChannels(*runs.front())) {
      bool everywhere = ch != a.channel;
      for (const sim::Run* run : runs) everywhere = everywhere && run->Has(ch);
      if (everywhere) candidates.push_back("gradient:" + ch);
    }
  }

  // The score of one candidate; +inf (with the reason) when a fold cannot fit it.
  auto score = [&](OffsetRule offset, int order, const std::vector<std::string>& terms, std::string& note) {
    PolyFitOptions o = base;
    o.offset = offset;
    o.order = order;
    o.terms = terms;
    try {
      return PolyCv(runs, folds, o);
    } catch (const NumericalError& e) {
      note = e.what();
      CvScore failed;
      failed.rms = std::numeric_limits<double>::infinity();
      failed.fold_ms.assign(folds.size(), std::numeric_limits<double>::infinity());
      return failed;
    }
  };
  auto record_step = [&](const std::string& candidate, double cv, bool accepted, const std::string& note) {
    record.steps.push_back({candidate, cv, accepted, note});
    return record.steps.size() - 1;
  };
  // Steps 1 and 3: the smallest order that no higher order beats.
  struct Choice {
    int order = 0;
    CvScore cv;
  };
  auto choose_order = [&](OffsetRule offset, const std::vector<std::string>& terms) {
    std::vector<CvScore> scores;
    std::vector<size_t> steps;
    for (int p = 1; p <= 5; ++p) {
      std::string note;
      scores.push_back(score(offset, p, terms, note));
      steps.push_back(record_step(Describe(offset, p, terms), scores.back().rms, false, note));
    }
    const int p = SmallestUnbeatenOrder(scores, a.min_gain);
    if (p == 0) return Choice{};  // none could be fitted
    record.steps[steps[static_cast<size_t>(p - 1)]].accepted = true;
    return Choice{p, scores[static_cast<size_t>(p - 1)]};
  };

  // Each offset's path: order, terms, order again.
  struct Path {
    OffsetRule offset = OffsetRule::kFitted;
    int order = 1;
    std::vector<std::string> terms;
    CvScore cv;
    int parameters = 0;
  };
  std::vector<Path> paths;
  for (const OffsetRule allowed : offsets) {
    Path path;
    path.offset = allowed;
    const Choice first = choose_order(allowed, {});
    if (first.order == 0) continue;
    path.order = first.order;
    path.cv = first.cv;
    for (;;) {
      CvScore best;
      best.rms = std::numeric_limits<double>::infinity();
      std::string best_term;
      size_t best_step = 0;
      for (const auto& term : candidates) {
        if (std::find(path.terms.begin(), path.terms.end(), term) != path.terms.end()) continue;
        std::vector<std::string> terms = path.terms;
        terms.push_back(term);
        std::string note;
        const CvScore s = score(allowed, path.order, terms, note);
        const size_t step = record_step(Describe(allowed, path.order, terms), s.rms, false, note);
        if (s.rms < best.rms) {
          best = s;
          best_term = term;
          best_step = step;
        }
      }
      if (best_term.empty() || !Beats(best, path.cv, a.min_gain)) break;
      path.terms.push_back(best_term);
      record.steps[best_step].accepted = true;
      path.cv = best;
    }
    if (!path.terms.empty()) {
      const Choice again = choose_order(allowed, path.terms);
      if (again.order > 0) {
        path.order = again.order;
        path.cv = again.cv;
      }
    }
    // Linear coefficients plus the profiled widths and time constants.
    path.parameters = path.order + (allowed == OffsetRule::kFitted ? 1 : 0);
    for (const auto& t : path.terms) path.parameters += t == "hysteresis" || t == "lag" ? 2 : 1;
    paths.push_back(path);
  }
  if (paths.empty()) {
    throw NumericalError(fmt::format("auto: no polynomial in {} could be fitted: {}", a.channel, record.steps.back().note));
  }
  // The offset: the path of fewest parameters that no other beats (ties: the lower score).
  std::stable_sort(paths.begin(), paths.end(), [](const Path& x, const Path& y) {
    return x.parameters != y.parameters ? x.parameters < y.parameters : x.cv.rms < y.cv.rms;
  });
  const Path* chosen = &paths.front();
  for (const auto& p : paths) {
    bool beaten = false;
    for (const auto& q : paths) beaten = beaten || (&q != &p && Beats(q.cv, p.cv, a.min_gain));
    if (!beaten) {
      chosen = &p;
      break;
    }
  }
  record_step("selected: " + Describe(chosen->offset, chosen->order, chosen->terms), chosen->cv.rms, true, "");

  PolyFitOptions o = base;
  o.offset = chosen->offset;
  o.order = chosen->order;
  o.terms = chosen->terms;
  PolyModel m = FitPoly(runs, o);
  m.selection = record;
  return m;
}

}  // namespace rlg::model
