// Stage 4, bias: every bias effect of the catalog on every target as an extra regressor of the
// linear bias fit (diagnosis_bias_fit.h), scored in sample and held out; the null bootstrap that
// sets their acceptance score. See model/diagnosis_engine.h.

#include <ceres/ceres.h>
#include <ceres/normal_prior.h>

#include <Eigen/QR>
#include <algorithm>
#include <fmt/format.h>
#include <fmt/ranges.h>

#include "diagnosis/engine.h"
#include "diagnosis/rank.h"
#include "diagnosis/screen.h"
#include "sim/noise.h"
#include "sim/stats.h"

namespace rlg::diagnosis {

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

}  // namespace

std::vector<Candidate> Engine::BiasCandidates(const Model& m, const std::vector<Prediction>& pred,
                                              const std::vector<Extra>& accepted, const std::set<std::string>& taken,
                                              const std::vector<Eigen::VectorXd>* bias_data,
                                              std::vector<std::vector<Extra>>* extras) const {
  const GyroConfig g = Build(nominal_, knobs_, m);
  const BiasDesign base = Design(m, pred, accepted, bias_data);
  const diagnosis::ResidualFit base_fit = ScoreBias(HeldOutBias(base));
  // In-sample fit of the baseline for the information criterion, at the fit resolution: rate
  // and gradient terms differ only in transients of a few minutes, which 100 s means blur.
  auto in_sample = [&](const BiasDesign& d) {
    const Eigen::VectorXd beta = FitBias(d, fit_);
    std::vector<std::vector<double>> series;
    for (int r : fit_) {
      const Eigen::VectorXd e = BiasResidual(d, beta, r);
      series.emplace_back(e.data(), e.data() + e.size());
    }
    return std::make_pair(diagnosis::Summarise(series), beta);
  };
  const auto [base_in, base_beta] = in_sample(base);

  // The gain of a candidate column (sim::ColumnGain), for effects that search a shape: the
  // drop of the in-sample sum of squares when it joins the fit, by Frisch-Waugh-Lovell: the
  // column centred per run (as FitBias centres), less its projection on the centred regressors
  // already in, against the baseline's residual. Only the fit runs: held-out runs stay unseen.
  Eigen::Index rows = 0;
  for (int r : fit_) rows += base.X[r].rows();
  Eigen::MatrixXd Xc(rows, base.X[fit_.front()].cols());
  Eigen::VectorXd e(rows);
  Eigen::Index at = 0;
  for (int r : fit_) {
    Xc.middleRows(at, base.X[r].rows()) = base.X[r].rowwise() - base.X[r].colwise().mean();
    e.segment(at, base.X[r].rows()) = BiasResidual(base, base_beta, r);
    at += base.X[r].rows();
  }
  const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(Xc);
  const Eigen::MatrixXd Q = qr.householderQ() * Eigen::MatrixXd::Identity(rows, qr.rank());
  const sim::ColumnGain gain = [&](const std::vector<std::vector<double>>& column) {
    Eigen::VectorXd x(rows);
    Eigen::Index at = 0;
    for (int r : fit_) {
      const auto& c = column[static_cast<size_t>(r)];
      const Eigen::Map<const Eigen::VectorXd> v(c.data(), static_cast<Eigen::Index>(c.size()));
      x.segment(at, v.size()) = v.array() - v.mean();
      at += v.size();
    }
    const double raw = x.squaredNorm();
    x -= Q * (Q.transpose() * x);
    const double xx = x.squaredNorm();
    // A column within the regressors' span (to round-off of its own size) adds nothing.
    if (!(xx > 1e-12 * raw)) return 0.0;
    const double xe = x.dot(e);
    return xe * xe / xx;
  };

  // Every bias effect of the catalog on every target: its term at unit coefficient as an extra
  // regressor (the function the simulator's BiasModel calls).
  struct Option {
    std::string cause, target;
    std::vector<Extra> extra;
    std::function<std::map<std::string, double>(const Eigen::VectorXd&)> to_params;
    int searched = 0;  // shape parameters searched on these data (sim::BiasRegressor)
  };
  std::vector<Option> options;
  const int first_extra = sim::NumBaselineRegressors(g.bias) + static_cast<int>(accepted.size());
  const sim::TargetSpace space{g, n_nodes_, {}};
  std::vector<const Eigen::MatrixXd*> tracks;
  for (const auto& p : pred) tracks.push_back(&p.T);
  for (const auto& effect : sim::Effects()) {
    if (effect->kind() != sim::EffectKind::kBias) continue;
    for (auto& reg : effect->Regressors(space, tracks, gain)) {
      options.push_back({effect->name(), reg.target,
                         {[column = reg.column](const Prediction& p, size_t k, int r) {
                           return column(sim::NodeTrack{p.T, p.Tdot}, k, r);
                         }},
                         [first_extra, parameters = reg.parameters](const Eigen::VectorXd& beta) {
                           return parameters(beta[first_extra]);
                         },
                         reg.searched_parameters});
    }
  }

  std::vector<Candidate> cands;
  std::map<std::string, size_t> best_of;  // one candidate per (cause, target): the best range
  for (const auto& opt : options) {
    const std::string key = opt.cause + "|" + CanonicalTarget(nominal_, opt.cause, opt.target);
    if (taken.count(key)) continue;
    std::vector<Extra> all_extra = accepted;
    all_extra.insert(all_extra.end(), opt.extra.begin(), opt.extra.end());
    const BiasDesign d = Design(m, pred, all_extra, bias_data);
    const diagnosis::ResidualFit held = ScoreBias(HeldOutBias(d));
    const auto [fin, beta] = in_sample(d);
    Candidate c;
    c.cause = opt.cause;
    c.target = opt.target;
    c.kind = "bias";
    c.parameters = opt.to_params(beta);
    c.score = diagnosis::InformationGain(base_in, fin, static_cast<int>(opt.extra.size()) + opt.searched);
    c.heldout_rms_ratio = diagnosis::HeldOutRmsRatio(base_fit.ssr, held.ssr);
    if (opt.searched > 0 && bias_data == nullptr) {
      // Where the searched column steps up and down, at the bias node's fit-block temperature
      // (the mean of the blocks either side).
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
      c.shape_note = fmt::format(
          "the data fix where {} steps, not its shape parameters apart: up at {} and down at {} °C of the "
          "bias node (its fit-block means); the parameters reported are one shape that steps there ({} of "
          "them searched, counted in the score)",
          opt.cause, EdgeList(up), EdgeList(down), opt.searched);
    }
    const auto it = best_of.find(key);
    if (it != best_of.end()) {
      if (cands[it->second].score >= c.score) continue;
      cands[it->second] = c;
      (*extras)[it->second] = opt.extra;
      continue;
    }
    best_of[key] = cands.size();
    cands.push_back(c);
    extras->push_back(opt.extra);
  }
  return cands;
}

NullBootstrap Engine::NullBiasThreshold(const std::vector<Prediction>& pred) const {
  // Parametric bootstrap (docs/diagnosis.md): bias data made of the calibrated baseline's
  // fitted bias plus the gyro file's own noise (ARW, bias instability, quantization: the
  // simulator's GyroNoise), block-averaged like the data. The best acceptable bias candidate's
  // score on each replicate is what noise alone reaches; slow bias instability makes it far
  // above the white-noise information criterion for slowly varying regressors (hysteresis).
  const BiasDesign base = Design(model_, pred, {});
  const Eigen::VectorXd beta = FitBias(base, fit_);
  std::vector<double> best;
  for (int b = 0; b < o_.null_replicates; ++b) {
    std::vector<Eigen::VectorXd> y(runs_.size());
    for (size_t r = 0; r < runs_.size(); ++r) {
      sim::GyroNoise noise(nominal_.noise, runs_[r].sample_period_s, static_cast<uint64_t>(b) + 1, r);
      std::vector<double> n(runs_[r].run->size());
      for (double& v : n) v = noise.Sample(0.0);
      y[r] = base.X[r] * beta + BlockMeans(n, static_cast<int>(r));
    }
    std::vector<std::vector<Extra>> extras;
    double top = -std::numeric_limits<double>::infinity();
    for (const auto& c : BiasCandidates(model_, pred, {}, {}, &y, &extras))
      if (c.heldout_rms_ratio >= o_.min_heldout_ratio) top = std::max(top, c.score);
    best.push_back(top);
  }
  NullBootstrap out;
  out.replicates = static_cast<int>(best.size());
  // The largest of the replicates: with 40 of them, a null dataset beats it ~2.5 % of the time.
  out.threshold = diagnosis::NullThreshold(best, o_.min_score);
  out.replicate_scores = std::move(best);
  return out;
}

std::string Engine::NullBootstrapNote(const NullBootstrap& null) const {
  const auto& best = null.replicate_scores;
  const auto passed = std::count_if(best.begin(), best.end(), [](double v) { return std::isfinite(v); });
  return fmt::format("bias acceptance: score >= {:.1f}, the best bias candidate's score on {} null replicates "
                     "(calibrated model + the gyro file's noise; in {} of them some candidate also passed the held-out "
                     "test); the information criterion alone asks {:.0f}",
                     null.threshold, best.size(), passed, o_.min_score);
}

}  // namespace rlg::diagnosis
