#include "diagnosis/network/bias_search.h"

#include <Eigen/QR>
#include <algorithm>
#include <fmt/format.h>
#include <fmt/ranges.h>
#include <cmath>
#include <functional>
#include <limits>
#include <map>
#include <stdexcept>
#include <utility>

#include "diagnosis/diagnose.h"
#include "diagnosis/statistics/power.h"
#include "diagnosis/statistics/score.h"
#include "diagnosis/statistics/screen.h"
#include "sim/bias_model.h"
#include "diagnosis/catalog/effect_search.h"

namespace rlg::diagnosis {

using sim::GyroConfig;

namespace {

/// "31.0 (x3), 47.1" for the values (°C) of `at` merged within 0.5 °C: the temperatures at
/// which a searched column steps one way.
std::string EdgeList(std::vector<double> at) {
  std::sort(at.begin(), at.end());
  std::vector<std::string> parts;
  for (size_t i = 0; i < at.size();) {
    size_t j = i;
    double sum = 0.0;
    while (j < at.size() && at[j] - at[i] <= 0.5) sum += at[j++];
    const size_t n = j - i;
    parts.push_back(n > 1 ? fmt::format("{:.1f} (x{})", sum / static_cast<double>(n), n)
                          : fmt::format("{:.1f}", sum));
    i = j;
  }
  return parts.empty() ? "nowhere" : fmt::format("{}", fmt::join(parts, ", "));
}

/// In-sample fit of a design for the information criterion, at the fit resolution: rate and
/// gradient terms differ only in transients of a few minutes, which 100 s means blur.
std::pair<ResidualFit, Eigen::VectorXd> InSample(const Problem& p, const BiasDesign& d) {
  const Eigen::VectorXd beta = FitBias(d, p.fit);
  std::vector<std::vector<double>> series;
  for (int r : p.fit) {
    const Eigen::VectorXd e = BiasResidual(d, beta, r);
    series.emplace_back(e.data(), e.data() + e.size());
  }
  return std::make_pair(Summarise(series), beta);
}

/// The gain of a candidate column (ColumnGain), for effects that search a shape: the drop
/// of the in-sample sum of squares when it joins the ordinary least-squares fit, by
/// Frisch-Waugh-Lovell (statistics/off_span.h): the column centred per run (as FitBias centres),
/// less its projection on the centred regressors already in, against the baseline's residual.
/// Only the fit runs: held-out runs stay unseen. (A shape's search needs only an order among
/// shapes; the shape found is then scored like any candidate.) With `shared`, a keyed column's
/// projection is kept there and found again (ShapeProjections).
class ProjectedGain final : public ColumnGain {
 public:
  ProjectedGain(const Problem& p, const BiasDesign& base, const Eigen::VectorXd& base_beta, ShapeProjections* shared)
      : fit_(p.fit), shared_(shared), span_(Span(p, base, base_beta)) {
    if (shared_) {
      if (shared_->rows < 0) shared_->rows = span_.rows(), shared_->rank = span_.rank();
      if (shared_->rows != span_.rows() || shared_->rank != span_.rank()) {
        throw std::logic_error(fmt::format("shape projections of {} rows and rank {} shared with a fit of {} and {}",
                                           shared_->rows, shared_->rank, span_.rows(), span_.rank()));
      }
    }
  }

  double operator()(const RunColumn& column) const override { return span_.Gain(Project(column)); }

  double Keyed(const std::vector<double>& key, const std::function<std::optional<RunColumn>()>& make) const override {
    if (!shared_) return ColumnGain::Keyed(key, make);
    const auto it = shared_->by_key.find(key);
    if (it != shared_->by_key.end()) return span_.Gain(it->second);
    const std::optional<RunColumn> column = make();
    OffSpan made;
    if (column) {
      made = Project(*column);
    } else {
      made.none = true;
    }
    const double gain = span_.Gain(made);
    if (shared_->doubles + made.Doubles() <= ShapeProjections::kMaxDoubles) {
      shared_->doubles += made.Doubles();
      shared_->by_key.emplace(key, std::move(made));
    }
    return gain;
  }

 private:
  /// The fit runs' centred baseline regressors (their span's orthonormal basis) and residual.
  static SpanComplement Span(const Problem& p, const BiasDesign& base, const Eigen::VectorXd& base_beta) {
    Eigen::Index rows = 0;
    for (int r : p.fit) rows += base.X[r].rows();
    Eigen::MatrixXd Xc(rows, base.X[p.fit.front()].cols());
    Eigen::VectorXd e(rows);
    Eigen::Index at = 0;
    for (int r : p.fit) {
      Xc.middleRows(at, base.X[r].rows()) = base.X[r].rowwise() - base.X[r].colwise().mean();
      e.segment(at, base.X[r].rows()) = BiasResidual(base, base_beta, r);
      at += base.X[r].rows();
    }
    const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(Xc);
    return SpanComplement(qr.householderQ() * Eigen::MatrixXd::Identity(rows, qr.rank()), std::move(e));
  }

  OffSpan Project(const RunColumn& column) const {
    std::vector<std::pair<const double*, size_t>> runs;
    for (int r : fit_) runs.emplace_back(column[static_cast<size_t>(r)].data(), column[static_cast<size_t>(r)].size());
    return span_.Project(runs);
  }

  std::vector<int> fit_;
  ShapeProjections* shared_;
  SpanComplement span_;
};

std::vector<std::vector<double>> FitResiduals(const Problem& p, const BiasDesign& d) {
  const Eigen::VectorXd beta = FitBias(d, p.fit);
  std::vector<std::vector<double>> segments;
  for (int r : p.fit) {
    const Eigen::VectorXd e = BiasResidual(d, beta, r);
    segments.emplace_back(e.data(), e.data() + e.size());
  }
  return segments;
}

/// The order of a search's noise models: that of least AIC (at most kMaxBiasArOrder) for the
/// baseline's ordinary least-squares residuals on the fit runs, fit blocks.
int NoiseOrder(const Problem& p, const BiasDesign& base) {
  return static_cast<int>(FitAr(FitResiduals(p, base), kMaxBiasArOrder).phi.size());
}

/// Spans per run of the cross-validation in time (CrossValidatedInTime): two folds of two
/// half-hour to hour-long spans per run of a few hours, each long beside the AR's 10 lags.
constexpr int kCrossValidationPieces = 4;

/// A candidate and the baseline, fitted by feasible generalised least squares (one
/// Cochrane-Orcutt iteration): the candidate's ordinary least-squares residuals give an AR model
/// of `order`, and both designs are prewhitened by it. The candidate's noise model, fitted on
/// residuals that hold no more than what the extended model leaves: a noise model fitted on the
/// baseline's residuals takes the missing term for noise (a hidden hysteresis 9x the noise scored
/// 29 so, where ordinary least squares gave 670), and with a noise model each the baseline's
/// would still absorb part of it (303).
struct Prewhitened {
  BiasDesign base, ext;
};

Prewhitened PrewhitenByCandidate(const Problem& p, const BiasDesign& base, const BiasDesign& ext, int order) {
  const ArModel noise = FitArOfOrder(FitResiduals(p, ext), order);
  return {Prewhiten(base, noise, p.bias_block_noise), Prewhiten(ext, noise, p.bias_block_noise)};
}

/// Residuals of a prewhitened design on data it was not fitted on, fit blocks: of the held-out
/// runs (HeldOutBias) when there are some, else of leave-one-run-out ([0]) and of two folds in
/// time ([1]).
std::vector<ResidualFit> HeldOutWhite(const Problem& p, const BiasDesign& white) {
  std::vector<std::vector<Eigen::VectorXd>> designs = {HeldOutBias(p, white)};
  if (p.held.empty()) designs.push_back(CrossValidatedInTime(white, p.fit, kCrossValidationPieces));
  std::vector<ResidualFit> out;
  for (const auto& held : designs) {
    std::vector<std::vector<double>> series;
    for (int r : p.Scored()) series.emplace_back(held[r].data(), held[r].data() + held[r].size());
    out.push_back(Summarise(series));
  }
  return out;
}

/// The held-out gain of the candidate over the baseline, both prewhitened by the candidate's
/// noise model (with a noise model each, a fold that cannot fit the candidate would predict as
/// the baseline does and still lose, its noise model not made for the term the baseline's
/// absorbed): the log-likelihood ratio of their held-out residuals on the held-out runs or,
/// without them, the better of leave-one-run-out and the folds in time. Each design is blind to
/// what its folds cannot share: a run that does not excite the effect (two runs, one a soak:
/// leaving one out fits it on the soak alone), or a stretch of time in which it does not act
/// (mode hops while warming up only). The null bootstrap applies the same rule, so the false
/// alarms it lets through are counted in its threshold.
double HeldOutGain(const Problem& p, const Prewhitened& w) {
  const std::vector<ResidualFit> b = HeldOutWhite(p, w.base), e = HeldOutWhite(p, w.ext);
  double best = -std::numeric_limits<double>::infinity();
  for (size_t i = 0; i < b.size(); ++i) best = std::max(best, LogLikelihoodRatio(b[i], e[i]));
  return best;
}

/// A bias effect on one target as columns of the regression.
struct Option {
  std::string cause, target;
  std::vector<Extra> extra;
  std::function<std::map<std::string, double>(const Eigen::VectorXd&)> to_params;
  int searched = 0;  // shape parameters searched on these data (BiasRegressor)
};

/// Every bias effect of the catalog on every target: its term at unit coefficient as an extra
/// regressor (the function the simulator's BiasModel calls), its coefficient the first after
/// the baseline's and the accepted ones.
std::vector<Option> Options(const Problem& p, const GyroConfig& g, const std::vector<Prediction>& pred,
                            size_t accepted, const ColumnGain& gain) {
  std::vector<Option> options;
  const int first_extra = sim::NumBaselineRegressors(g.bias) + static_cast<int>(accepted);
  const TargetSpace space{g, p.n_nodes, {}};
  std::vector<const Eigen::MatrixXd*> tracks;
  for (const auto& q : pred) tracks.push_back(&q.T);
  for (const auto& effect : EffectSearches()) {
    if (effect->effect().kind() != sim::EffectKind::kBias) continue;
    for (auto& reg : effect->Regressors(space, tracks, gain)) {
      options.push_back({effect->name(), reg.target,
                         {[column = reg.column](const Prediction& q, size_t k, int r) {
                           return column(NodeTrack{q.T, q.Tdot}, k, r);
                         }},
                         [first_extra, parameters = reg.parameters](const Eigen::VectorXd& beta) {
                           return parameters(beta[first_extra]);
                         },
                         reg.searched_parameters});
    }
  }
  return options;
}

/// Where the searched column of `opt` steps up and down, at the bias node's fit-block
/// temperature (the mean of the blocks either side).
std::string ShapeNote(const GyroConfig& g, const std::vector<Prediction>& pred, const Option& opt) {
  std::vector<double> up, down;
  for (size_t r = 0; r < pred.size(); ++r) {
    const Eigen::MatrixXd& T = pred[r].T;
    double last = T.cols() > 0 ? opt.extra[0](pred[r], 0, static_cast<int>(r)) : 0.0;
    for (Eigen::Index k = 1; k < T.cols(); ++k) {
      const double now = opt.extra[0](pred[r], static_cast<size_t>(k), static_cast<int>(r));
      const double at = 0.5 * (T(g.bias.node, k) + T(g.bias.node, k - 1));
      if (now > last) up.push_back(at);
      if (now < last) down.push_back(at);
      last = now;
    }
  }
  return fmt::format(
      "the data fix where {} steps, not its shape parameters apart: up at {} and down at {} °C of the "
      "bias node (its fit-block means); the parameters reported are one shape that steps there ({} of "
      "them searched, counted in the score)",
      opt.cause, EdgeList(up), EdgeList(down), opt.searched);
}

}  // namespace

BiasSearch SearchBias(const Problem& p, const Model& m, const std::vector<Prediction>& pred,
                      const std::vector<Extra>& accepted, const std::set<CauseTarget>& taken,
                      const std::vector<Eigen::VectorXd>* bias_data, ShapeProjections* shared) {
  const GyroConfig g = Build(p.nominal, p.knobs, m);
  const bool replicate = bias_data != nullptr;
  const BiasDesign base_raw = Design(p, m, pred, accepted, bias_data);
  // The held-out RMS ratio is the report's (score-block means as measured); a null replicate
  // needs only the scores.
  const ResidualFit base_ratio = replicate ? ResidualFit{} : ScoreBias(p, HeldOutBias(p, base_raw));
  const int order = NoiseOrder(p, base_raw);
  const ProjectedGain gain(p, base_raw, FitBias(base_raw, p.fit), shared);
  const std::vector<Option> options = Options(p, g, pred, accepted.size(), gain);
  BiasSearch out;
  std::map<CauseTarget, size_t> best_of;  // one candidate per (cause, target): the best range
  std::vector<Prewhitened> whitened;      // a replicate's, per candidate: for its held-out gains below
  for (const auto& opt : options) {
    const CauseTarget key{opt.cause, CanonicalTarget(p.nominal, opt.cause, opt.target)};
    if (taken.count(key)) continue;
    std::vector<Extra> all_extra = accepted;
    all_extra.insert(all_extra.end(), opt.extra.begin(), opt.extra.end());
    const BiasDesign d = Design(p, m, pred, all_extra, bias_data);
    const Prewhitened w = PrewhitenByCandidate(p, base_raw, d, order);
    const auto [ext_in, beta] = InSample(p, w.ext);
    const int k = static_cast<int>(opt.extra.size()) + opt.searched;
    Candidate c;
    c.cause = opt.cause;
    c.target = opt.target;
    c.kind = CandidateKind::kBias;
    c.parameters = opt.to_params(beta);
    c.score = LogLikelihoodRatio(InSample(p, w.base).first, ext_in) - k * std::log(std::max(ext_in.n, 2));
    if (!replicate) {
      c.heldout_gain = HeldOutGain(p, w);
      c.heldout_rms_ratio = HeldOutRmsRatio(base_ratio.ssr, ScoreBias(p, HeldOutBias(p, d)).ssr);
      if (opt.searched > 0) c.shape_note = ShapeNote(g, pred, opt);
    }
    const auto it = best_of.find(key);
    if (it != best_of.end()) {
      if (out.candidates[it->second].score >= c.score) continue;
      out.candidates[it->second] = c;
      out.extras[it->second] = opt.extra;
      out.counted[it->second] = k;
      if (replicate) whitened[it->second] = w;
      continue;
    }
    best_of[key] = out.candidates.size();
    out.candidates.push_back(c);
    out.extras.push_back(opt.extra);
    out.counted.push_back(k);
    if (replicate) whitened.push_back(w);
  }
  if (replicate) {
    // A replicate's threshold needs the best score whose held-out gain passes: held-out gains
    // from the best score down to the first that passes, the rest left NaN (not computed).
    std::vector<size_t> by_score(out.candidates.size());
    for (size_t i = 0; i < by_score.size(); ++i) by_score[i] = i;
    auto score = [&](size_t i) {  // a NaN score (a degenerate fit) last: it never sets the threshold
      const double v = out.candidates[i].score;
      return std::isnan(v) ? -std::numeric_limits<double>::infinity() : v;
    };
    std::stable_sort(by_score.begin(), by_score.end(), [&](size_t a, size_t b) { return score(a) > score(b); });
    for (Candidate& c : out.candidates) c.heldout_gain = std::numeric_limits<double>::quiet_NaN();
    for (size_t i : by_score) {
      out.candidates[i].heldout_gain = HeldOutGain(p, whitened[i]);
      if (out.candidates[i].heldout_gain > p.options.min_heldout_gain) break;
    }
  }
  return out;
}

PairedScores::PairedScores(const Problem& p, const Model& m, const std::vector<Prediction>& pred,
                           const std::vector<Extra>& accepted, const std::vector<Extra>& leader, int k_leader)
    : p_(p), m_(m), pred_(pred), accepted_(accepted), leader_(leader), k_leader_(k_leader),
      order_(NoiseOrder(p, Design(p, m, pred, accepted))), d_leader_(Design(p, m, pred, Beside(leader))) {}

std::vector<Extra> PairedScores::Beside(std::vector<Extra> extra) const {
  extra.insert(extra.begin(), accepted_.begin(), accepted_.end());
  return extra;
}

double PairedScores::Difference(const std::vector<Extra>& rival, int k_rival) const {
  std::vector<Extra> both = leader_;
  both.insert(both.end(), rival.begin(), rival.end());
  const ArModel noise = FitArOfOrder(FitResiduals(p_, Design(p_, m_, pred_, Beside(both))), order_);
  const ResidualFit l = InSample(p_, Prewhiten(d_leader_, noise, p_.bias_block_noise)).first;
  const ResidualFit r = InSample(p_, Prewhiten(Design(p_, m_, pred_, Beside(rival)), noise, p_.bias_block_noise)).first;
  return LogLikelihoodRatio(l, r) - (k_rival - k_leader_) * std::log(std::max(r.n, 2));
}

namespace {

/// The catalog's start of a reported size parameter: its own, or for one reported as a
/// combination (hysteresis's k_heating - k_cooling) that of the parameter it applies as.
double StartSize(const EffectSearch& effect, const std::string& reported) {
  const sim::ParameterMap start = effect.Start();
  if (start.count(reported)) return start.at(reported);
  for (const auto& [name, per_unit] : effect.FromReported({{reported, 1.0}}))
    if (per_unit != 0.0 && start.count(name)) return start.at(name) / per_unit;
  throw std::logic_error(fmt::format("BiasPower: no start for {} of {}", reported, effect.name()));
}

}  // namespace

std::vector<EffectPower> BiasPower(const Problem& p, const Model& m, const std::vector<Prediction>& pred,
                                   double threshold) {
  const GyroConfig g = Build(p.nominal, p.knobs, m);
  const BiasDesign base_raw = Design(p, m, pred, {});
  // The noise as the score sees it on data without the effect: the AR model of the baseline's
  // ordinary least-squares residuals, of the search's order.
  const ArModel noise = FitArOfOrder(FitResiduals(p, base_raw), NoiseOrder(p, base_raw));
  const BiasDesign base = Prewhiten(base_raw, noise, p.bias_block_noise);
  const double sd = noise.sigma > 0.0 ? noise.sigma : 1.0;
  // The prewhitened fit rows, centred per run (FitBias's offsets), stacked; Q spans the
  // baseline's columns there: what the baseline can take up of a candidate's column.
  Eigen::Index rows = 0;
  for (int r : p.fit) rows += base.X[r].rows();
  auto stack = [&](const BiasDesign& d, Eigen::Index col) {
    Eigen::VectorXd v(rows);
    Eigen::Index at = 0;
    for (int r : p.fit) {
      const auto n = d.X[r].rows();
      if (n > 0) v.segment(at, n) = d.X[r].col(col).array() - d.X[r].col(col).mean();
      at += n;
    }
    return v;
  };
  Eigen::MatrixXd Xb(rows, base.X[p.fit.front()].cols());
  for (Eigen::Index j = 0; j < Xb.cols(); ++j) Xb.col(j) = stack(base, j);
  const Eigen::MatrixXd Q = KnobBasis(Xb);
  const double ln_n = std::log(static_cast<double>(std::max<Eigen::Index>(rows, 2)));
  const double inf = std::numeric_limits<double>::infinity();
  const ProjectedGain gain(p, base_raw, FitBias(base_raw, p.fit), nullptr);
  const int first_extra = sim::NumBaselineRegressors(g.bias);
  // Per (cause, canonical target), its column of most noncentrality (a searched shape's forms).
  std::vector<EffectPower> out;
  std::vector<Eigen::VectorXd> unit;  // each signature at unit length (zero where the baseline takes all)
  std::vector<double> critical;
  std::vector<int> dof;
  std::map<CauseTarget, size_t> index;
  for (const Option& opt : Options(p, g, pred, 0, gain)) {
    const BiasDesign w = Prewhiten(Design(p, m, pred, opt.extra), noise, p.bias_block_noise);
    const Eigen::VectorXd x = stack(w, first_extra);
    const Eigen::VectorXd sig = (x - Q * (Q.transpose() * x)) / sd;  // per unit coefficient
    // What the baseline leaves of a column it takes whole is round-off, not power.
    const double per_unit = sig.allFinite() && sig.squaredNorm() > 1e-12 * x.squaredNorm() / (sd * sd)
                                ? sig.squaredNorm() : 0.0;
    // The size parameter: the one the coefficient moves (affinely: value(c) = value(0) + c slope).
    Eigen::VectorXd beta = Eigen::VectorXd::Zero(first_extra + 1);
    const auto at0 = opt.to_params(beta);
    beta[first_extra] = 1.0;
    const auto at1 = opt.to_params(beta);
    EffectPower e;
    e.cause = opt.cause;
    e.target = opt.target;
    double slope = 0.0;
    for (const auto& [k, v] : at1)
      if (v != at0.at(k)) e.parameter = k, slope = v - at0.at(k);
    if (e.parameter.empty()) throw std::logic_error(fmt::format("BiasPower: {} has no size parameter", opt.cause));
    // The start: the catalog's typical size, in the coefficient's units.
    e.start = std::abs(StartSize(RequireSearch(opt.cause), e.parameter));
    const double c_start = e.start / slope;
    beta[first_extra] = c_start;
    e.at = opt.to_params(beta);
    e.lambda_at_start = per_unit * c_start * c_start;
    const CauseTarget key{opt.cause, CanonicalTarget(p.nominal, opt.cause, opt.target)};
    const auto it = index.find(key);
    if (it != index.end() && out[it->second].lambda_at_start >= e.lambda_at_start) continue;
    const int k = static_cast<int>(opt.extra.size());
    const double crit = threshold + (k + opt.searched) * ln_n;
    e.detected = e.lambda_at_start > 0.0
                     ? e.start * std::sqrt(DetectionNoncentrality(crit, k, kPowerLevel) / e.lambda_at_start)
                     : inf;
    e.named = e.detected;
    const Eigen::VectorXd u = per_unit > 0.0 ? Eigen::VectorXd(sig / std::sqrt(per_unit)) : Eigen::VectorXd(sig * 0.0);
    if (it != index.end()) {
      out[it->second] = e;
      unit[it->second] = u;
      critical[it->second] = crit;
      dof[it->second] = k;
      continue;
    }
    index[key] = out.size();
    out.push_back(e);
    unit.push_back(u);
    critical.push_back(crit);
    dof.push_back(k);
  }
  NameApart(out, unit, critical, dof);
  return out;
}

std::vector<Candidate> FirstBiasCandidates(const Problem& p, const Calibration& cal) {
  if (!p.has_bias) return {};
  return SearchBias(p, cal.model, SimulateAll(p, cal.model, p.All()), {}, {}).candidates;
}

}  // namespace rlg::diagnosis
