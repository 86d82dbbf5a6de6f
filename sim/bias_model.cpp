#include "sim/bias_model.h"

#include <cmath>

namespace rlg::sim {

double BiasParams::ModeSpacing_C() const {
  return mode_spacing_C > 0.0 ? mode_spacing_C : wavelength_m / (path_length_m * cte_per_C);
}

BiasModel::BiasModel(BiasParams params) : p_(std::move(params)), mode_spacing_C_(p_.ModeSpacing_C()) {}

BiasModel::State BiasModel::Start(const Eigen::Ref<const Eigen::VectorXd>& T) const {
  State s;
  s.T_lock = T[p_.node];
  s.mode = 0;
  for (const auto& h : p_.hysteresis) s.last_T.push_back(T[h.node]);
  s.hysteresis_dph.assign(p_.hysteresis.size(), 0.0);
  return s;
}

double BiasModel::Evaluate(const Eigen::Ref<const Eigen::VectorXd>& T, const Eigen::Ref<const Eigen::VectorXd>& Tdot,
                           State& s) const {
  const double dT = T[p_.node] - p_.reference_C;
  double b = p_.b0_dph + p_.b1_dph_per_C * dT + p_.b2_dph_per_C2 * dT * dT;

  double flow = p_.langmuir_dph_per_mA * p_.langmuir_current_imbalance_mA;
  for (const auto& g : p_.langmuir_gradients) flow += g.k_dph_per_C * (T[g.a] - T[g.b]);
  b += (1.0 + p_.langmuir_temperature_coeff_per_C * dT) * flow;

  double u = (T[p_.node] - s.T_lock) / mode_spacing_C_ - s.mode;
  if (p_.mode_hops) {
    while (u > p_.mode_hop_range_modes) {
      ++s.mode;
      u -= 1.0;
    }
    while (u < -p_.mode_hop_range_modes) {
      --s.mode;
      u += 1.0;
    }
    b += p_.mode_hop_step_dph * s.mode;
  }
  b += p_.plc_dph_per_wavelength * u;

  for (const auto& r : p_.rate_terms) b += r.k_dph_per_C_per_min * Tdot[r.node] * 60.0;
  for (const auto& g : p_.extra_gradients) b += g.k_dph_per_C * (T[g.a] - T[g.b]);
  for (size_t i = 0; i < p_.hysteresis.size(); ++i) {
    const auto& h = p_.hysteresis[i];
    const double step = T[h.node] - s.last_T[i];
    s.hysteresis_dph[i] += (step >= 0.0 ? h.k_heating_dph_per_C : h.k_cooling_dph_per_C) * step;
    s.last_T[i] = T[h.node];
    b += s.hysteresis_dph[i];
  }
  return b;
}

}  // namespace rlg::sim
