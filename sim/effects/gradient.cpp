#include "sim/effects/gradient.h"

#include "sim/limits.h"

namespace rlg::sim {
namespace {

// [est] A typical size: a tenth of the default gyro's Langmuir anode-block coefficient.
constexpr double kTypical = 0.05;

/// Node pairs a < b among the candidates, without the bias model's Langmuir gradients.
std::vector<std::pair<int, int>> Pairs(const TargetSpace& space) {
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

std::string PairName(const GyroConfig& g, std::pair<int, int> ab) {
  return g.network.nodes[ab.first].name + "-" + g.network.nodes[ab.second].name;
}

}  // namespace

GradientEffect::GradientEffect()
    : Effect("bias.gradient", EffectKind::kBias,
             {{"k_dph_per_C", "°/h/°C", false, -1.0, 1.0,
               "[est] bias follows spatial gradients (Wu & Gu, PLANS 2002; Honeywell US 8,781,778, docs/physics.md); the "
               "default gyro's largest, Langmuir flow along the anode leg, is 0.45 °/h/°C",
               -limits::kMaxBiasPerC, limits::kMaxBiasPerC, std::nullopt, kTypical}}) {}

std::vector<std::string> GradientEffect::Targets(const TargetSpace& space) const {
  std::vector<std::string> out;
  for (const auto& ab : Pairs(space)) out.push_back(PairName(space.gyro, ab));
  return out;
}

void GradientEffect::Apply(const std::string& target, const ParameterMap& p, GyroConfig& gyro) const {
  const auto [a, b] = ResolvePair(gyro, target, false);
  gyro.bias.extra_gradients.push_back({a, b, p.at("k_dph_per_C")});
}

std::vector<BiasRegressor> GradientEffect::Regressors(const TargetSpace& space,
                                                      const std::vector<const Eigen::MatrixXd*>&, const ColumnGain&) const {
  std::vector<BiasRegressor> out;
  for (const auto& [a, b] : Pairs(space)) {
    out.push_back({PairName(space.gyro, {a, b}),
                   [a = a, b = b](const NodeTrack& x, size_t k, int) {
                     const auto i = static_cast<Eigen::Index>(k);
                     return Bias_dph(1.0, x.T(a, i), x.T(b, i));
                   },
                   [](double c) { return ParameterMap{{"k_dph_per_C", c}}; }});
  }
  return out;
}

double GradientEffect::Implausibility(const ParameterMap& reported) const {
  return Relative(reported, "k_dph_per_C", kTypical);
}

std::string GradientEffect::SeparationAdvice(const std::set<std::string>& tied_causes, bool) const {
  // Gradients that differ by one the model nearly spans (from the anodes or from the cathode:
  // one discharge heats both) part only where those nodes' own heating changes.
  if (tied_causes != std::set<std::string>{name()}) return {};
  return "gradients between different node pairs separate where those nodes heat differently: power-on "
         "warm-ups (power cycles) or a discharge-current step within a run";
}

}  // namespace rlg::sim
