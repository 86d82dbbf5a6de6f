// The bias effects' searches (effect_search.h) whose term has no shape to search: each is its
// physics' term (sim/effects/, the function BiasModel calls) at unit coefficient on every target.

#include <memory>

#include "diagnosis/catalog/searches.h"
#include "sim/effects/gradient.h"
#include "sim/effects/hysteresis.h"
#include "sim/effects/temperature_rate.h"

namespace rlg::diagnosis::catalog {
namespace {

using Fit = ParameterSearch::Fit;

/// bias.temperature_rate: every node, named as NodeTarget does.
class TemperatureRate final : public EffectSearch {
 public:
  // [est] A typical size: 0.05 °/h per °C/min moves the bias by 0.05 °/h during a 1 °C/min
  // ramp, a few times a navigation-grade gyro's 100 s noise (docs/physics.md).
  static constexpr double kTypical = 0.05;
  TemperatureRate() : EffectSearch("bias.temperature_rate", {{"k_dph_per_C_per_min", {kTypical}}}) {}
  std::vector<std::string> Targets(const TargetSpace& space) const override {
    std::vector<std::string> out;
    for (int node = 0; node < space.nodes; ++node) out.push_back(sim::NodeTarget(space.gyro, node));
    return out;
  }
  std::vector<BiasRegressor> Regressors(const TargetSpace& space, const std::vector<const Eigen::MatrixXd*>&,
                                        const ColumnGain&) const override {
    std::vector<BiasRegressor> out;
    for (int node = 0; node < space.nodes; ++node) {
      out.push_back({sim::NodeTarget(space.gyro, node),
                     [node](const NodeTrack& x, size_t k, int) {
                       return sim::TemperatureRateEffect::Bias_dph(1.0, x.Tdot(node, static_cast<Eigen::Index>(k)));
                     },
                     [](double c) { return sim::ParameterMap{{"k_dph_per_C_per_min", c}}; }});
    }
    return out;
  }
  bool ComputedFromTracks() const override { return true; }
  double Implausibility(const sim::ParameterMap& reported) const override {
    return Relative(reported, "k_dph_per_C_per_min", kTypical);
  }
};

/// Node pairs a < b among the candidates, without the bias model's Langmuir gradients.
std::vector<std::pair<int, int>> GradientPairs(const TargetSpace& space) {
  std::vector<std::pair<int, int>> out;
  for (int a = 0; a < space.nodes; ++a) {
    for (int b = a + 1; b < space.nodes; ++b) {
      bool in_baseline = false;
      for (const auto& gr : space.gyro.bias.langmuir_gradients)
        if ((gr.a == a && gr.b == b) || (gr.a == b && gr.b == a)) in_baseline = true;
      if (!in_baseline) out.emplace_back(a, b);
    }
  }
  return out;
}

std::string PairName(const sim::GyroConfig& g, std::pair<int, int> ab) {
  return g.network.nodes[ab.first].name + "-" + g.network.nodes[ab.second].name;
}

/// bias.gradient: every pair of nodes that is not already a Langmuir gradient of the bias model.
class Gradient final : public EffectSearch {
 public:
  // [est] A typical size: a tenth of the default gyro's Langmuir anode-block coefficient.
  static constexpr double kTypical = 0.05;
  Gradient() : EffectSearch("bias.gradient", {{"k_dph_per_C", {kTypical}}}) {}
  std::vector<std::string> Targets(const TargetSpace& space) const override {
    std::vector<std::string> out;
    for (const auto& ab : GradientPairs(space)) out.push_back(PairName(space.gyro, ab));
    return out;
  }
  std::vector<BiasRegressor> Regressors(const TargetSpace& space, const std::vector<const Eigen::MatrixXd*>&,
                                        const ColumnGain&) const override {
    std::vector<BiasRegressor> out;
    for (const auto& [a, b] : GradientPairs(space)) {
      out.push_back({PairName(space.gyro, {a, b}),
                     [a = a, b = b](const NodeTrack& x, size_t k, int) {
                       const auto i = static_cast<Eigen::Index>(k);
                       return sim::GradientEffect::Bias_dph(1.0, x.T(a, i), x.T(b, i));
                     },
                     [](double c) { return sim::ParameterMap{{"k_dph_per_C", c}}; }});
    }
    return out;
  }
  bool ComputedFromTracks() const override { return true; }
  double Implausibility(const sim::ParameterMap& reported) const override {
    return Relative(reported, "k_dph_per_C", kTypical);
  }
  std::string SeparationAdvice(const std::set<std::string>& tied_causes, bool) const override {
    // Gradients that differ by one the model nearly spans (from the anodes or from the cathode:
    // one discharge heats both) part only where those nodes' own heating changes.
    if (tied_causes != std::set<std::string>{name()}) return {};
    return "gradients between different node pairs separate where those nodes heat differently: power-on "
           "warm-ups (power cycles) or a discharge-current step within a run";
  }
};

/// bias.hysteresis: every node. Only k_heating - k_cooling can be told from a linear term of
/// the baseline (the sum of all steps is the node's change since power-on): the fit reports
/// that difference and applies it as k_heating with k_cooling = 0.
class Hysteresis final : public EffectSearch {
 public:
  // [est] A typical size of k_heating - k_cooling: a loop 0.4 °/h wide after a 40 °C ramp up
  // and down, above the default gyro's intrinsic b1 (0.006 °/h/°C).
  static constexpr double kTypical = 0.01;
  static constexpr const char* kDifference = "k_heating_minus_cooling_dph_per_C";
  Hysteresis()
      : EffectSearch("bias.hysteresis", {{"k_heating_dph_per_C", {kTypical}}, {"k_cooling_dph_per_C", {0.0}}}) {}
  std::vector<std::string> Targets(const TargetSpace& space) const override {
    std::vector<std::string> out;
    for (int node = 0; node < space.nodes; ++node) out.push_back(space.gyro.network.nodes[node].name);
    return out;
  }
  std::vector<BiasRegressor> Regressors(const TargetSpace& space, const std::vector<const Eigen::MatrixXd*>& T_runs,
                                        const ColumnGain&) const override {
    // Heating increments of the node since power-on, from the tracks given. Cooling increments
    // are the node's change minus these, already spanned by the baseline's linear term. The
    // column shares its data by value: it outlives this call when a candidate is accepted.
    std::vector<BiasRegressor> out;
    for (int node = 0; node < space.nodes; ++node) {
      auto heat = std::make_shared<std::vector<std::vector<double>>>(T_runs.size());
      for (size_t r = 0; r < T_runs.size(); ++r) {
        const Eigen::MatrixXd& T = *T_runs[r];
        auto& h = (*heat)[r];
        h.resize(static_cast<size_t>(T.cols()));
        double last = h.empty() ? 0.0 : T(node, 0), accumulated = 0.0;
        for (size_t k = 0; k < h.size(); ++k)
          h[k] = sim::HysteresisEffect::Bias_dph(1.0, 0.0, T(node, static_cast<Eigen::Index>(k)), last, accumulated);
      }
      out.push_back({space.gyro.network.nodes[node].name,
                     [heat](const NodeTrack&, size_t k, int r) { return (*heat)[static_cast<size_t>(r)][k]; },
                     [](double c) { return sim::ParameterMap{{kDifference, c}}; }});
    }
    return out;
  }
  sim::ParameterMap FromReported(const sim::ParameterMap& reported) const override {
    return {{"k_heating_dph_per_C", reported.at(kDifference)}, {"k_cooling_dph_per_C", 0.0}};
  }
  bool ComputedFromTracks() const override { return true; }
  double Implausibility(const sim::ParameterMap& reported) const override {
    return Relative(reported, kDifference, kTypical);
  }
};

/// bias.play: every node, and no regressor: its width is a shape the linear bias search cannot
/// fit, and bias.hysteresis stands for direction dependence there.
class Play final : public EffectSearch {
 public:
  // [est] A typical size: 0.01 °/h/°C through a 2 °C play leaves branches 0.02 °/h apart, a
  // few times a navigation-grade gyro's 100 s noise.
  static constexpr double kTypicalK = 0.01;
  static constexpr double kTypicalWidth_C = 2.0;
  Play() : EffectSearch("bias.play", {{"k_dph_per_C", {kTypicalK}}, {"width_C", {kTypicalWidth_C, Fit::kShape}}}) {}
  std::vector<std::string> Targets(const TargetSpace& space) const override {
    std::vector<std::string> out;
    for (int node = 0; node < space.nodes; ++node) out.push_back(space.gyro.network.nodes[node].name);
    return out;
  }
  double Implausibility(const sim::ParameterMap& reported) const override {
    return Relative(reported, "k_dph_per_C", kTypicalK);
  }
};

}  // namespace

std::unique_ptr<const EffectSearch> TemperatureRateSearch() { return std::make_unique<TemperatureRate>(); }
std::unique_ptr<const EffectSearch> GradientSearch() { return std::make_unique<Gradient>(); }
std::unique_ptr<const EffectSearch> HysteresisSearch() { return std::make_unique<Hysteresis>(); }
std::unique_ptr<const EffectSearch> PlaySearch() { return std::make_unique<Play>(); }

}  // namespace rlg::diagnosis::catalog
