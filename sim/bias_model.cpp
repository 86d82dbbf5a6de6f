#include "sim/bias_model.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "sim/effects/gradient.h"
#include "sim/effects/hysteresis.h"
#include "sim/effects/play.h"
#include "sim/effects/mode_hop.h"
#include "sim/effects/temperature_rate.h"

namespace rlg::sim {

double BiasParams::ModeSpacing_C() const {
  return mode_spacing_C > 0.0 ? mode_spacing_C : wavelength_m / (path_length_m * cte_per_C);
}

double IntrinsicBias_dph(double b0_dph, double b1_dph_per_C, double b2_dph_per_C2, double dT_C) {
  return b0_dph + b1_dph_per_C * dT_C + b2_dph_per_C2 * dT_C * dT_C;
}

double LangmuirBias_dph(const BiasParams& p, const double* T_C, double dT_C) {
  double flow = p.langmuir_dph_per_mA * p.langmuir_current_imbalance_mA;
  for (const auto& g : p.langmuir_gradients) flow += g.k_dph_per_C * LegGradient_C(g, T_C);
  return (1.0 + p.langmuir_temperature_coeff_per_C * dT_C) * flow;
}

int NumBaselineRegressors(const BiasParams& p) { return 2 + 2 * static_cast<int>(p.langmuir_gradients.size()); }

void BaselineRegressors(const BiasParams& p, const Eigen::Ref<const Eigen::VectorXd>& T_C,
                        Eigen::Ref<Eigen::RowVectorXd, 0, Eigen::InnerStride<>> x) {
  const double dT = BiasNodeExcess_C(p, T_C[p.node]);
  Eigen::Index c = 0;
  x[c++] = IntrinsicBias_dph(0.0, 1.0, 0.0, dT);
  x[c++] = IntrinsicBias_dph(0.0, 0.0, 1.0, dT);
  for (const auto& g : p.langmuir_gradients) {
    const double G = LegGradient_C(g, T_C.data());
    x[c++] = G;
    x[c++] = G * dT;
  }
}

std::vector<double> BaselineCoefficients(const BiasParams& b) {
  std::vector<double> beta = {b.b1_dph_per_C + b.langmuir_temperature_coeff_per_C * b.langmuir_dph_per_mA *
                                                   b.langmuir_current_imbalance_mA +
                                  b.plc_dph_per_wavelength / b.ModeSpacing_C(),
                              b.b2_dph_per_C2};
  for (const auto& g : b.langmuir_gradients) {
    beta.push_back(g.k_dph_per_C);
    beta.push_back(g.k_dph_per_C * b.langmuir_temperature_coeff_per_C);
  }
  return beta;
}

BiasModel::BiasModel(BiasParams params) : p_(std::move(params)), mode_spacing_C_(p_.ModeSpacing_C()) {}

BiasModel::State BiasModel::Start(const Eigen::Ref<const Eigen::VectorXd>& T) const {
  State s;
  // Without bias.mode_hop the control powers on centred (and never resets: Evaluate).
  const double centre = p_.mode_hops ? p_.mode_hop_centre_C : std::numeric_limits<double>::quiet_NaN();
  const PlcLock on = PowerOn(T[p_.node], centre, mode_spacing_C_);
  s.T_lock = on.T_lock_C;
  s.mode = on.mode;
  for (const auto& h : p_.hysteresis) s.last_T.push_back(T[h.node]);
  s.hysteresis_dph.assign(p_.hysteresis.size(), 0.0);
  for (const auto& q : p_.play) s.play_C.push_back(T[q.node]);
  return s;
}

double BiasModel::Evaluate(const Eigen::Ref<const Eigen::VectorXd>& T, const Eigen::Ref<const Eigen::VectorXd>& Tdot,
                           State& s) const {
  double b;  // a block of one sample (a Ref to a vector is contiguous: inner stride 1)
  Evaluate(T.data(), Tdot.data(), static_cast<size_t>(T.size()), 1, &b, s);
  return b;
}

void BiasModel::Evaluate(const double* T, const double* Tdot, size_t stride, size_t n, double* out, State& s) const {
  // Term by term over the samples, each term a loop the compiler can vectorise and added to
  // each sample's bias in the same order whatever n: the same numbers for a block as for its
  // samples one at a time.
  constexpr size_t kChunk = 256;
  std::array<double, kChunk> dT;
  const double plc = p_.plc_dph_per_wavelength;
  const auto node = static_cast<size_t>(p_.node);
  for (size_t done = 0; done < n; done += kChunk) {
    const size_t m = std::min(kChunk, n - done);
    const double* const Tj = T + done * stride;
    const double* const Tdotj = Tdot + done * stride;
    double* const b = out + done;
    for (size_t j = 0; j < m; ++j) {
      dT[j] = BiasNodeExcess_C(p_, Tj[j * stride + node]);
      b[j] = IntrinsicBias_dph(p_.b0_dph, p_.b1_dph_per_C, p_.b2_dph_per_C2, dT[j]);
    }
    for (size_t j = 0; j < m; ++j) b[j] += LangmuirBias_dph(p_, Tj + j * stride, dT[j]);
    if (p_.mode_hops) {
      for (size_t j = 0; j < m; ++j) {
        const double u = PathLengthTravel(Tj[j * stride + node], s.T_lock, mode_spacing_C_, p_.mode_hop_range_modes, s.mode);
        b[j] += ModeHopEffect::Bias_dph(p_.mode_hop_step_dph, s.mode);
        b[j] += plc * u;
      }
    } else {
      // Unlimited range: the mode stays where it is and the travel never resets.
      const double T_lock = s.T_lock, mode = s.mode;
      for (size_t j = 0; j < m; ++j) b[j] += plc * (LockTravel(Tj[j * stride + node], T_lock, mode_spacing_C_) - mode);
    }
    for (const auto& r : p_.rate_terms) {
      const auto i = static_cast<size_t>(r.node);
      for (size_t j = 0; j < m; ++j) b[j] += TemperatureRateEffect::Bias_dph(r.k_dph_per_C_per_min, Tdotj[j * stride + i]);
    }
    for (const auto& g : p_.extra_gradients) {
      const auto a = static_cast<size_t>(g.a), c = static_cast<size_t>(g.b);
      for (size_t j = 0; j < m; ++j) b[j] += GradientEffect::Bias_dph(g.k_dph_per_C, Tj[j * stride + a], Tj[j * stride + c]);
    }
    for (size_t i = 0; i < p_.hysteresis.size(); ++i) {
      const auto& h = p_.hysteresis[i];
      const auto k = static_cast<size_t>(h.node);
      for (size_t j = 0; j < m; ++j) {
        b[j] += HysteresisEffect::Bias_dph(h.k_heating_dph_per_C, h.k_cooling_dph_per_C, Tj[j * stride + k], s.last_T[i],
                                           s.hysteresis_dph[i]);
      }
    }
    for (size_t i = 0; i < p_.play.size(); ++i) {
      const auto& q = p_.play[i];
      const auto k = static_cast<size_t>(q.node);
      for (size_t j = 0; j < m; ++j) b[j] += PlayEffect::Bias_dph(q.k_dph_per_C, q.width_C, q.reference_C, Tj[j * stride + k], s.play_C[i]);
    }
  }
}

}  // namespace rlg::sim
