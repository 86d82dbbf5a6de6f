#include "diagnosis/without_network/candidates.h"

#include <algorithm>
#include <cmath>
#include <fmt/format.h>
#include <memory>

#include "model/causal_operators.h"
#include "diagnosis/catalog/effect_search.h"

namespace rlg::diagnosis {

namespace {

/// The measured channels as a gyro whose nodes they are: node i named channels[i], read by its
/// own sensor without lag, the bias on the polynomial's channel. Effects take their targets
/// from it (TargetSpace) and name them by channel; nothing simulates it.
sim::GyroConfig ChannelsAsNodes(const MeasuredProblem& p) {
  sim::GyroConfig g;
  g.name = "measured channels";
  for (size_t i = 0; i < p.channels.size(); ++i) {
    g.network.nodes.push_back({p.channels[i], 1.0});
    sim::SensorSpec s;
    s.channel = p.channels[i];
    s.node = static_cast<int>(i);
    g.sensors.push_back(s);
  }
  g.bias.node = p.channel_index;
  return g;
}

/// The catalog's bias effects computed from tracks, on every target, as fixed columns.
void CatalogCandidates(const MeasuredProblem& p, std::vector<MeasuredCandidate>& out) {
  const sim::GyroConfig g = ChannelsAsNodes(p);
  const TargetSpace space{g, static_cast<int>(p.channels.size()), p.channels};
  std::vector<const Eigen::MatrixXd*> tracks;
  for (const auto& T : p.T) tracks.push_back(&T);
  const GainOfColumn no_search([](const RunColumn&) { return 0.0; });  // they search no shape
  for (const auto& effect : EffectSearches()) {
    if (effect->effect().kind() != sim::EffectKind::kBias || !effect->ComputedFromTracks()) continue;
    for (const auto& reg : effect->Regressors(space, tracks, no_search)) {
      RunColumns column;
      for (size_t r = 0; r < p.runs.size(); ++r) {
        const NodeTrack track{p.T[r], p.Tdot[r]};
        Eigen::VectorXd v(p.T[r].cols());
        for (Eigen::Index k = 0; k < v.size(); ++k) v[k] = reg.column(track, static_cast<size_t>(k), static_cast<int>(r));
        column.push_back(std::move(v));
      }
      MeasuredCandidate c;
      c.cause = effect->name();
      c.target = reg.target;
      c.column = [column = std::move(column)](double) { return column; };
      c.parameters = [parameters = reg.parameters](double coefficient, double) { return parameters(coefficient); };
      out.push_back(std::move(c));
    }
  }
}

/// A model-family term of the channel as a column: block means of term(t, T) per sample, the
/// operator made afresh at each run's first sample.
template <typename Term>
RunColumns TermColumns(const MeasuredProblem& p, const Term& term) {
  return BlockMeansOf(p, [&](int r) {
    const sim::Run& run = *p.runs[static_cast<size_t>(r)];
    return term(run.t_s, run.Column(p.channel));
  });
}

}  // namespace

std::vector<MeasuredCandidate> MeasuredCandidates(const MeasuredProblem& p, const model::PolySpec& baseline) {
  std::vector<MeasuredCandidate> out;
  CatalogCandidates(p, out);
  std::vector<double> periods;
  double longest = 0.0;
  for (const auto& u : p.units) {
    periods.push_back(u.prepared.sample_period_s);
    longest = std::max(longest, u.prepared.run->t_s.back() - u.prepared.run->t_s.front());
  }
  std::nth_element(periods.begin(), periods.begin() + static_cast<std::ptrdiff_t>(periods.size() / 2), periods.end());
  const double dt = periods[periods.size() / 2], span = baseline.range_C[1] - baseline.range_C[0];

  MeasuredCandidate lag;
  lag.cause = "poly.lag";
  lag.target = p.channel;
  lag.searched = 1;
  lag.lo = 2.0 * dt;
  lag.hi = longest / 2.0;
  lag.column = [&p](double tau) {
    return TermColumns(p, [tau](const std::vector<double>& t, const std::vector<double>& T) {
      model::FirstOrderLag op(tau);
      std::vector<double> v(T.size());
      for (size_t k = 0; k < T.size(); ++k) v[k] = op.Next(t[k], T[k]) - T[k];
      return v;
    });
  };
  lag.parameters = [](double k, double tau) { return sim::ParameterMap{{"k_dph_per_C", k}, {"tau_s", tau}}; };
  if (lag.hi > lag.lo) out.push_back(lag);

  MeasuredCandidate loop;
  loop.cause = "poly.hysteresis";
  loop.target = p.channel;
  loop.searched = 1;
  loop.lo = span / 200.0;
  loop.hi = span / 2.0;
  loop.column = [&p](double w) {
    return TermColumns(p, [w](const std::vector<double>&, const std::vector<double>& T) {
      model::PlayOperator op(w);
      std::vector<double> v(T.size());
      for (size_t k = 0; k < T.size(); ++k) v[k] = T[k] - op.Next(T[k]);
      return v;
    });
  };
  // The loop's half height k w / 2 beside k and w: what a heating/cooling hysteresis of
  // +-0.05 °/h is quoted as; k alone says nothing of its size.
  loop.parameters = [](double k, double w) {
    return sim::ParameterMap{{"k_dph_per_C", k}, {"width_C", w}, {"amplitude_dph", 0.5 * k * w}};
  };
  if (loop.hi > loop.lo) out.push_back(loop);

  // The baseline's next power d^(order+1), on the baseline's range and reference: the blocked
  // cross-validation that chose the order holds out the same phase of identical cycles in every
  // fold, and on a FOG-like log cut into its three cycles it chose a line for a quadratic.
  if (baseline.order < 5) {
    MeasuredCandidate next;
    next.cause = "poly.order";
    next.target = p.channel;
    const int n = baseline.order + 1;
    const double lo = baseline.range_C[0], hi = baseline.range_C[1], ref = baseline.reference_C;
    next.column = [column = TermColumns(p, [n, lo, hi, ref](const std::vector<double>&, const std::vector<double>& T) {
                     std::vector<double> v(T.size());
                     for (size_t k = 0; k < T.size(); ++k) v[k] = std::pow(std::clamp(T[k], lo, hi) - ref, n);
                     return v;
                   })](double) { return column; };
    next.parameters = [n](double c, double) {
      return sim::ParameterMap{{"order", n}, {fmt::format("c{0}_dph_per_C{0}", n), c}};
    };
    out.push_back(std::move(next));
  }
  return out;
}

}  // namespace rlg::diagnosis
