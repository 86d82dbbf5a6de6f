#include "model/poly_fit.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <fmt/format.h>
#include <fmt/ranges.h>
#include <limits>
#include <set>

#include "model/allan.h"
#include "model/pairs.h"
#include "model/training_span.h"
#include "sim/errors.h"
#include "sim/limits.h"

namespace rlg::model {

bool PolyFitOptions::IsValid(std::string* error) const {
  std::string why;
  if (order < 1 || order > 5) why = fmt::format("order must be 1 to 5 (got {})", order);
  else if (channel.size() < 2 || channel[0] != 'T') why = fmt::format("channel '{}': expected a temperature channel such as T1", channel);
  else if (reference_C && !(*reference_C >= sim::limits::kMinTemperature_C && *reference_C <= sim::limits::kMaxTemperature_C))
    why = fmt::format("reference temperature {:g} °C is outside {:g}...{:g} °C", *reference_C, sim::limits::kMinTemperature_C,
                      sim::limits::kMaxTemperature_C);
  else if (!(b0_window_s > 0.0 && b0_window_s <= sim::limits::kMaxAbsTime_s))
    why = fmt::format("the B0 window must be a positive number of seconds (got {:g})", b0_window_s);
  else if (!(rate_tau_s >= 0.0 && rate_tau_s <= sim::limits::kMaxLag))
    why = fmt::format("the rate term's tau_r must be 0 (the rule) or a positive number of seconds up to {:g} (got {:g})",
                      sim::limits::kMaxLag, rate_tau_s);
  else if (linear.IsValid(&why) && profile.IsValid(&why)) {
    for (const auto& t : terms) {
      if (t == "gradient") continue;  // every other channel: expanded on the data
      if (!ParseTerm(t, channel, &why)) break;
    }
  }
  if (error) *error = why;
  return why.empty();
}

PolyFitOptions PresetOptions(PolyPreset preset) {
  PolyFitOptions o;
  o.order = 3;
  o.preset = preset;
  if (preset == PolyPreset::kPx4) {
    o.offset = OffsetRule::kFitted;
  } else if (preset == PolyPreset::kArduPilot) {
    o.offset = OffsetRule::kPowerOn;
    o.reference_C = 35.0;
  } else {
    throw InputError(fmt::format("preset '{}': expected px4 or ardupilot", PolyPresetName(preset)));
  }
  return o;
}

double RateTau(double sample_period_s) { return 10.0 * sample_period_s; }

std::array<bool, 2> HeatsAndCools(const std::vector<const sim::Run*>& runs, const RowMask& mask,
                                  const std::string& channel, double w) {
  bool heats = false, cools = false;
  for (size_t r = 0; r < runs.size(); ++r) {
    PlayOperator play(w);
    const auto& T = runs[r]->Column(channel);
    for (size_t k = 0; k < T.size(); ++k) {
      const double h = T[k] - play.Next(T[k]);
      if (!mask.empty() && !mask[r][k]) continue;
      heats = heats || h >= 0.5 * w * (1.0 - 1e-9);
      cools = cools || h <= -0.5 * w * (1.0 - 1e-9);
    }
  }
  return {heats, cools};
}

namespace {

bool Used(const RowMask& mask, size_t r, size_t k) { return mask.empty() || mask[r][k]; }

/// The regressor of term `term` alone over every used sample, in BuildDesign's row order (the
/// operators of PolyRegressors), referred to its mean over the B0 window with a power-on
/// offset, as BuildDesign refers every column.
Eigen::VectorXd TermColumn(const std::vector<const sim::Run*>& runs, const RowMask& mask, const PolySpec& spec,
                           const PolyTerm& term, Eigen::Index rows) {
  Eigen::VectorXd z(rows);
  Eigen::Index at = 0;
  std::vector<double> v;
  for (size_t r = 0; r < runs.size(); ++r) {
    const auto& T = runs[r]->Column(spec.channel);
    const auto& t = runs[r]->t_s;
    PlayOperator play(term.width_C);
    FirstOrderLag lag(term.tau_s);
    v.resize(T.size());
    for (size_t k = 0; k < T.size(); ++k) {
      v[k] = term.kind == TermKind::kHysteresis ? T[k] - play.Next(T[k]) : lag.Next(t[k], T[k]) - T[k];
    }
    double reference = 0.0;
    if (spec.offset == OffsetRule::kPowerOn && !T.empty()) {
      size_t count = 0;
      for (size_t k = 0; k < T.size() && t[k] < t.front() + spec.b0_window_s; ++k, ++count) reference += v[k];
      reference /= static_cast<double>(std::max<size_t>(count, 1));
    }
    for (size_t k = 0; k < T.size(); ++k)
      if (Used(mask, r, k)) z[at++] = v[k] - reference;
  }
  return z;
}

/// Each factor's range over the used samples (a rate through the term's low-pass from power-on).
void SetFactorRanges(const std::vector<const sim::Run*>& runs, const RowMask& mask, PolyTerm& term) {
  for (Factor& f : term.factors) {
    double lo = std::numeric_limits<double>::infinity(), hi = -lo;
    for (size_t r = 0; r < runs.size(); ++r) {
      const auto& a = runs[r]->Column(f.channel);
      const std::vector<double>* b = f.minus.empty() ? nullptr : &runs[r]->Column(f.minus);
      RateFilter rate(term.tau_s);
      for (size_t k = 0; k < a.size(); ++k) {
        double v = b ? a[k] - (*b)[k] : a[k];
        if (f.rate) v = rate.Next(runs[r]->t_s[k], v);
        if (!Used(mask, r, k)) continue;
        lo = std::min(lo, v);
        hi = std::max(hi, v);
      }
    }
    f.range = {lo, hi};
  }
}

/// What data would separate the coefficients named (the end of an ill-conditioned fit's message).
std::string Hint(const PolySpec& spec, const std::vector<std::string>& involved) {
  std::vector<std::string> parts;
  bool poly = false;
  for (const auto& name : involved) {
    if (name.size() == 2 && name[0] == 'c') poly = true;
  }
  if (poly) {
    parts.push_back(fmt::format("an order-{} polynomial needs {} to cover a range at {} or more distinct temperatures "
                                "(the training data span {:.4g} ... {:.4g} °C)",
                                spec.order, spec.channel, spec.order + 1, spec.range_C[0], spec.range_C[1]));
  }
  for (const auto& t : spec.terms) {
    if (std::find(involved.begin(), involved.end(), t.Name()) == involved.end()) continue;
    switch (t.kind) {
      case TermKind::kRate:
        parts.push_back(fmt::format("the rate term needs {} to change at different rates", spec.channel));
        break;
      case TermKind::kHysteresis:
        parts.push_back(fmt::format("the hysteresis term needs {} to heat and cool", spec.channel));
        break;
      case TermKind::kLag:
        parts.push_back(fmt::format("the lag term needs {} to change at different rates", spec.channel));
        break;
      case TermKind::kGradient:
        parts.push_back(fmt::format("the gradient term needs {} - {} to vary apart from {}", t.channel, spec.channel,
                                    spec.channel));
        break;
      case TermKind::kProduct:
        parts.push_back(fmt::format("the term {} needs its factors to vary apart from each other and from {} (a "
                                    "gradient that moves at several temperatures: soaks and ramps)",
                                    t.Name(), spec.channel));
        break;
    }
  }
  return parts.empty() ? std::string("more varied data would") : fmt::format("{}", fmt::join(parts, "; "));
}

/// The residual sum of squares of the linear fit as a function of the profiled terms'
/// parameters (variable projection): the other columns' thin QR once; each evaluation projects
/// the profiled terms' columns off them and solves their small least squares.
class TermsProfile {
 public:
  TermsProfile(const std::vector<const sim::Run*>& runs, const RowMask& mask, const PolySpec& spec,
               const std::vector<size_t>& profiled)
      : runs_(runs), mask_(mask), spec_(spec), profiled_(profiled) {
    const Design d = BuildDesign(runs, PolyRegressors(spec), mask);
    const Eigen::Index n = d.X.rows(), p = d.X.cols();
    const auto first_term = static_cast<Eigen::Index>(spec.CoefficientNames().size() - spec.terms.size());
    std::vector<Eigen::Index> keep;
    for (Eigen::Index c = 0; c < p; ++c) {
      const bool is_profiled = c >= first_term && std::find(profiled.begin(), profiled.end(), static_cast<size_t>(c - first_term)) != profiled.end();
      if (!is_profiled) keep.push_back(c);
    }
    Eigen::MatrixXd X0(n, static_cast<Eigen::Index>(keep.size()));
    for (size_t c = 0; c < keep.size(); ++c) {
      X0.col(static_cast<Eigen::Index>(c)) = d.X.col(keep[c]);
      const double norm = X0.col(static_cast<Eigen::Index>(c)).norm();
      if (norm > 0.0) X0.col(static_cast<Eigen::Index>(c)) /= norm;
    }
    const Eigen::HouseholderQR<Eigen::MatrixXd> qr(X0);
    Q_ = qr.householderQ() * Eigen::MatrixXd::Identity(n, X0.cols());
    residual_ = d.y - Q_ * (Q_.transpose() * d.y);
    rss0_ = residual_.squaredNorm();
    rows_ = n;
  }
  /// Profiled term `which`'s column at parameter x, projected off the other columns.
  Eigen::VectorXd Perp(size_t which, double x) const {
    PolyTerm term = spec_.terms[profiled_[which]];
    (term.kind == TermKind::kHysteresis ? term.width_C : term.tau_s) = x;
    const Eigen::VectorXd z = TermColumn(runs_, mask_, spec_, term, rows_);
    Eigen::VectorXd perp = z - Q_ * (Q_.transpose() * z);
    // A column (numerically) inside the others' span explains nothing more.
    if (!(perp.squaredNorm() > 1e-20 * z.squaredNorm())) perp.setZero();
    return perp;
  }
  double Sse(const std::vector<const Eigen::VectorXd*>& perps) const {
    const auto k = static_cast<Eigen::Index>(perps.size());
    Eigen::MatrixXd G(k, k);
    Eigen::VectorXd g(k);
    for (Eigen::Index i = 0; i < k; ++i) {
      g[i] = perps[static_cast<size_t>(i)]->dot(residual_);
      for (Eigen::Index j = 0; j < k; ++j) G(i, j) = perps[static_cast<size_t>(i)]->dot(*perps[static_cast<size_t>(j)]);
    }
    const Eigen::LDLT<Eigen::MatrixXd> ldlt(G);
    if (ldlt.info() != Eigen::Success || !(ldlt.vectorD().minCoeff() > 1e-12 * std::max(1e-300, ldlt.vectorD().maxCoeff()))) {
      // Degenerate: the best of the columns alone.
      double best = rss0_;
      for (Eigen::Index i = 0; i < k; ++i)
        if (G(i, i) > 0.0) best = std::min(best, rss0_ - g[i] * g[i] / G(i, i));
      return best;
    }
    return rss0_ - g.dot(ldlt.solve(g));
  }

 private:
  const std::vector<const sim::Run*>& runs_;
  const RowMask& mask_;
  const PolySpec& spec_;
  std::vector<size_t> profiled_;
  Eigen::MatrixXd Q_;
  Eigen::VectorXd residual_;
  double rss0_ = 0.0;
  Eigen::Index rows_ = 0;
};

/// Fits the profiled terms' parameters (the header's search) into spec.terms.
void Profile(const std::vector<const sim::Run*>& runs, const RowMask& mask, PolySpec& spec,
             const std::vector<size_t>& profiled, const std::vector<std::array<double, 2>>& bounds,
             const ProfileOptions& o) {
  const TermsProfile profile(runs, mask, spec, profiled);
  const size_t k = profiled.size();
  std::vector<std::vector<double>> grid(k);
  std::vector<std::vector<Eigen::VectorXd>> perps(k);
  for (size_t j = 0; j < k; ++j) {
    grid[j] = LogGrid(bounds[j][0], bounds[j][1], o.grid_points);
    for (double x : grid[j]) perps[j].push_back(profile.Perp(j, x));
  }
  // Every combination of grid points (k is 1 or 2: one hysteresis and one lag at most).
  std::vector<size_t> at(k, 0), best_at(k, 0);
  double best = std::numeric_limits<double>::infinity();
  for (;;) {
    std::vector<const Eigen::VectorXd*> columns;
    for (size_t j = 0; j < k; ++j) columns.push_back(&perps[j][at[j]]);
    const double v = profile.Sse(columns);
    if (v < best) {
      best = v;
      best_at = at;
    }
    size_t j = 0;
    while (j < k && ++at[j] == grid[j].size()) at[j++] = 0;
    if (j == k) break;
  }
  std::vector<double> x(k);
  std::vector<Eigen::VectorXd> current(k);
  for (size_t j = 0; j < k; ++j) {
    x[j] = grid[j][best_at[j]];
    current[j] = perps[j][best_at[j]];
  }
  // Golden section of each about its grid neighbours, the others held (three rounds with two).
  const int rounds = k > 1 ? 3 : 1;
  for (int round = 0; round < rounds; ++round) {
    for (size_t j = 0; j < k; ++j) {
      const size_t i = best_at[j], m = grid[j].size();
      auto f = [&](double value) {
        const Eigen::VectorXd trial = profile.Perp(j, value);
        std::vector<const Eigen::VectorXd*> columns;
        for (size_t l = 0; l < k; ++l) columns.push_back(l == j ? &trial : &current[l]);
        return profile.Sse(columns);
      };
      const ProfileResult r = GoldenOnLogScale(f, grid[j][i > 0 ? i - 1 : 0], grid[j][std::min(i + 1, m - 1)], x[j], best,
                                               o.tolerance);
      x[j] = r.x;
      best = r.f;
      current[j] = profile.Perp(j, x[j]);
    }
  }
  for (size_t j = 0; j < k; ++j) {
    PolyTerm& t = spec.terms[profiled[j]];
    (t.kind == TermKind::kHysteresis ? t.width_C : t.tau_s) = x[j];
  }
}

/// The training data's fitted temperature range (°C), median sample period (s) and longest run (s).
/// The channel's span over the used samples (model/training_span.h); refuses data without
/// samples, at one temperature or of single-sample runs.
TrainingSpan CheckedSpan(const std::vector<const sim::Run*>& runs, const PolyFitOptions& o, const RowMask& mask) {
  const TrainingSpan span = SpanOf(runs, o.channel, [&](size_t r, size_t k) { return Used(mask, r, k); });
  if (!(span.hi >= span.lo)) throw InputError("poly fit: no samples to fit");
  if (!(span.hi > span.lo)) {
    throw NumericalError(fmt::format("{} stays at {:.4g} °C in every training sample: a polynomial in it cannot be "
                                     "fitted; the data must cover a range of temperatures",
                                     o.channel, span.lo));
  }
  if (span.dt == 0.0) throw InputError("poly fit: every run has fewer than 2 samples");
  return span;
}

/// The channels a gradient term `parsed` reaches: its own, or for "gradient" every other
/// temperature channel all runs share (refusing data with none).
std::vector<std::string> GradientChannels(const std::vector<const sim::Run*>& runs, const PolyFitOptions& o,
                                          const PolyTerm& parsed, bool every_gradient) {
  std::vector<std::string> gradient_channels;
  if (!every_gradient) {
    gradient_channels.push_back(parsed.channel);
    return gradient_channels;
  }
  for (const auto& ch : TemperatureChannels(*runs.front())) {
    bool everywhere = ch != o.channel;
    for (const sim::Run* run : runs) everywhere = everywhere && run->Has(ch);
    if (everywhere) gradient_channels.push_back(ch);
  }
  if (gradient_channels.empty()) {
    throw InputError(fmt::format("{}: the gradient term needs a second temperature channel beside {}; the data "
                                 "have none ({})",
                                 runs.front()->Where(), o.channel, fmt::join(runs.front()->names, ",")));
  }
  return gradient_channels;
}

/// Refuses a product term (`text` as given) whose factors name a channel some run lacks.
void CheckFactorChannels(const std::vector<const sim::Run*>& runs, const std::string& text, const PolyTerm& t) {
  for (const auto& f : t.factors) {
    for (const std::string* ch : {&f.channel, &f.minus}) {
      if (ch->empty()) continue;
      for (const sim::Run* run : runs) {
        if (!run->Has(*ch)) {
          throw InputError(fmt::format("term '{}': {} has no temperature channel '{}' (columns: {})", text, run->Where(),
                                       *ch, fmt::join(run->names, ",")));
        }
      }
    }
  }
}

/// The options' terms into spec.terms, in the order given, with their starting parameters;
/// "gradient" expands to every other channel the runs share.
void AddTerms(const std::vector<const sim::Run*>& runs, const PolyFitOptions& o, const RowMask& mask,
              const TrainingSpan& data, PolySpec& spec) {
  const double dt = data.dt, longest = data.longest, span = data.hi - data.lo;
  std::set<std::string> seen;
  for (const auto& text : o.terms) {
    const bool every_gradient = text == "gradient";
    const PolyTerm parsed = every_gradient ? PolyTerm{TermKind::kGradient, "", 0.0, 0.0, {}} : *ParseTerm(text, o.channel, nullptr);
    const TermKind kind = parsed.kind;
    auto add = [&](PolyTerm t) {
      if (t.kind == TermKind::kGradient && t.channel == o.channel) {
        throw InputError(fmt::format("term '{}': a gradient needs a channel other than {} itself", text, o.channel));
      }
      if (!seen.insert(t.Name()).second) throw InputError(fmt::format("term '{}' is named twice", t.Name()));
      spec.terms.push_back(t);
    };
    if (kind == TermKind::kGradient) {
      for (const auto& ch : GradientChannels(runs, o, parsed, every_gradient)) {
        PolyTerm t;
        t.kind = kind;
        t.channel = ch;
        add(t);
      }
      continue;
    }
    PolyTerm t = parsed;
    CheckFactorChannels(runs, text, t);
    if (kind == TermKind::kRate || t.HasRate()) t.tau_s = o.rate_tau_s > 0.0 ? o.rate_tau_s : RateTau(dt);
    if (kind == TermKind::kProduct) SetFactorRanges(runs, mask, t);
    if (kind == TermKind::kHysteresis) t.width_C = span / 10.0;
    if (kind == TermKind::kLag) t.tau_s = std::sqrt(2.0 * dt * longest / 2.0);
    add(t);
  }
}

/// Fits the hysteresis widths (°C) and lag time constants (s) of spec.terms by profile, within
/// bounds set by the span, the sample period and the longest run.
void ProfileTerms(const std::vector<const sim::Run*>& runs, const PolyFitOptions& o, const RowMask& mask,
                  const TrainingSpan& data, PolySpec& spec) {
  const double dt = data.dt, longest = data.longest, span = data.hi - data.lo;
  std::vector<size_t> profiled;
  std::vector<std::array<double, 2>> bounds;
  for (size_t j = 0; j < spec.terms.size(); ++j) {
    const PolyTerm& t = spec.terms[j];
    if (t.kind != TermKind::kHysteresis && t.kind != TermKind::kLag) continue;
    const bool width = t.kind == TermKind::kHysteresis;
    const double bound_lo = width ? span / 200.0 : 2.0 * dt, bound_hi = width ? span / 2.0 : longest / 2.0;
    if (!(bound_hi > bound_lo)) {
      throw NumericalError(fmt::format("the lag term's time constant cannot be fitted: the runs last {:g} s at {:g} s "
                                       "samples, too short to tell a lag from none",
                                       longest, dt));
    }
    profiled.push_back(j);
    bounds.push_back({bound_lo, bound_hi});
  }
  if (!profiled.empty()) Profile(runs, mask, spec, profiled, bounds, o.profile);
}

/// The model of spec with the linear fit's coefficients (°/h per unit of each regressor), their
/// errors and the fit's figures.
PolyModel ModelOf(const std::vector<const sim::Run*>& runs, const PolyFitOptions& o, const PolySpec& spec,
                  const LinearFit& fit) {
  PolyModel m;
  m.spec = spec;
  m.preset = o.preset;
  const auto names = spec.CoefficientNames();
  const auto units = spec.CoefficientUnits();
  for (size_t i = 0; i < names.size(); ++i) {
    Coefficient c;
    c.name = names[i];
    c.unit = units[i];
    c.value = fit.beta[static_cast<Eigen::Index>(i)];
    if (fit.standard_error.size() > 0) {
      c.standard_error = fit.standard_error[static_cast<Eigen::Index>(i)];
      c.dof = fit.dof_per_coefficient[static_cast<Eigen::Index>(i)];
    }
    m.coefficients.push_back(c);
  }
  m.stderr_method = fit.stderr_method;
  m.clusters = fit.clusters;
  m.condition_number = fit.condition_number;
  m.residual_rms_dph = fit.residual_rms_dph;
  for (const sim::Run* run : runs) m.runs.push_back(run->id);
  return m;
}

}  // namespace

PolyModel FitPoly(const std::vector<const sim::Run*>& runs, const PolyFitOptions& o, const RowMask& mask) {
  std::string invalid;
  if (!o.IsValid(&invalid)) throw InputError("poly fit: " + invalid);
  if (runs.empty()) throw InputError("poly fit: no runs to fit");
  for (const sim::Run* run : runs) {
    if (!run->Has(o.channel)) {
      throw InputError(fmt::format("{} has no temperature channel '{}' (columns: {})", run->Where(), o.channel,
                                   fmt::join(run->names, ",")));
    }
  }
  PolySpec spec;
  spec.channel = o.channel;
  spec.order = o.order;
  spec.offset = o.offset;
  spec.b0_window_s = o.b0_window_s;
  spec.extrapolate = o.extrapolate;

  const TrainingSpan data = CheckedSpan(runs, o, mask);
  spec.range_C = {data.lo, data.hi};
  spec.reference_C = o.reference_C ? *o.reference_C : 0.5 * (data.lo + data.hi);
  const double span = data.hi - data.lo;
  AddTerms(runs, o, mask, data, spec);

  // Hysteresis needs both branches: a play operator a tenth of the span wide must be pushed
  // up and down (heating and cooling of at least that much).
  for (const auto& t : spec.terms) {
    if (t.kind != TermKind::kHysteresis) continue;
    const auto [heats, cools] = HeatsAndCools(runs, mask, o.channel, span / 10.0);
    if (!heats || !cools) {
      throw NumericalError(fmt::format("the hysteresis term needs {} to heat and to cool by at least a tenth of its span "
                                       "({:.3g} °C) in the training data; it only {}",
                                       o.channel, span / 10.0, heats ? "heats" : cools ? "cools" : "wanders less than that"));
    }
  }
  ProfileTerms(runs, o, mask, data, spec);

  LinearFitOptions lo_opts = o.linear;
  lo_opts.hint = [&spec](const std::vector<std::string>& involved) { return Hint(spec, involved); };
  const PolyRegressors regressors(spec);
  const Design design = BuildDesign(runs, regressors, mask);
  const LinearFit fit = FitLinear(design, lo_opts);
  return ModelOf(runs, o, spec, fit);
}

}  // namespace rlg::model
