#pragma once
// Data made from the polynomial models' own form (model/poly_model.h) for the fit, coverage,
// selection and compensator tests: a chamber cycle of temperatures, a bias from a known model
// (its regressors from PolyRegressors, the form the fit assumes) and correlated noise.

#include <boost/random/mersenne_twister.hpp>
#include <boost/random/normal_distribution.hpp>
#include <cmath>
#include <string>
#include <vector>

#include "model/poly_model.h"
#include "sim/trace.h"

namespace rlg::model {

/// A chamber cycle like the IMU log of data/imu-thermal-cycle: 1 h at `dt_s`, the channel T1
/// swinging between about -10 and +60 °C through heating and cooling at rates that change
/// (two sines of 50 and 17 min), T2 following T1 through a 600 s lag plus 2 °C of self-heating
/// that rises over the first 20 min.
inline sim::Run CycleRun(const std::string& id, double dt_s = 2.0, double hours = 1.0, double phase = 0.0) {
  sim::Run r;
  r.id = id;
  auto& T1 = r.AddColumn("T1");
  auto& T2 = r.AddColumn("T2");
  r.AddColumn("bias_dph");
  double lagged = 0.0;
  const double two_pi = 2.0 * std::acos(-1.0);
  for (double t = 0.0; t <= hours * 3600.0 + 1e-9; t += dt_s) {
    const double T = 25.0 + 30.0 * std::sin(two_pi * t / 3000.0 + phase) + 6.0 * std::sin(two_pi * t / 1000.0 + 1.0 + phase);
    lagged = t == 0.0 ? T : lagged + (1.0 - std::exp(-dt_s / 600.0)) * (T - lagged);
    r.t_s.push_back(t);
    T1.push_back(T);
    T2.push_back(lagged + 2.0 * (1.0 - std::exp(-t / 1200.0)));
  }
  r.columns[2].resize(r.size());
  return r;
}

/// A warm-up or a ramp of a gyro like the default one, 2 h at `dt_s`: the ambient holds `from_C`
/// for 30 min, then moves at `rate_C_per_min` to `to_C` and holds it; T1 (the block) follows it
/// through a 14 min lag and self-heats by 1.5 °C over 25 min; T2 (the anode) runs 1 °C warmer
/// after 20 min of discharge heating, and lags the ambient more (21 min), so the gradient
/// T2 - T1 moves with the ramp's rate as well as with the warm-up: a soak alone leaves it
/// nearly fixed, a ramp moves it apart from T1.
inline sim::Run ChamberRun(const std::string& id, double from_C, double to_C, double rate_C_per_min, double dt_s = 2.0) {
  sim::Run r;
  r.id = id;
  auto& T1 = r.AddColumn("T1");
  auto& T2 = r.AddColumn("T2");
  r.AddColumn("bias_dph");
  double block = from_C, anode = from_C;
  for (double t = 0.0; t <= 7200.0 + 1e-9; t += dt_s) {
    double ambient = from_C;
    if (t > 1800.0 && rate_C_per_min != 0.0) {
      const double moved = rate_C_per_min * (t - 1800.0) / 60.0;
      ambient = from_C + (to_C > from_C ? std::min(moved, to_C - from_C) : std::max(moved, to_C - from_C));
    }
    if (t > 0.0) {
      block += (1.0 - std::exp(-dt_s / 840.0)) * (ambient - block);
      anode += (1.0 - std::exp(-dt_s / 1260.0)) * (ambient - anode);
    }
    r.t_s.push_back(t);
    T1.push_back(block + 1.5 * (1.0 - std::exp(-t / 1500.0)));
    T2.push_back(anode + 2.5 * (1.0 - std::exp(-t / 1200.0)));
  }
  r.columns[2].resize(r.size());
  return r;
}

/// Correlated noise: AR(1) with correlation time `tau_samples` (in samples; 0: white) and
/// standard deviation `sd` (stationary from the first sample).
struct Ar1 {
  double sd = 0.0;
  double tau_samples = 0.0;
};

/// Writes bias = offset + beta . g + noise into the run's bias_dph, g the regressors of `spec`
/// (fitted offset: the constant is beta's first entry and `offset` adds to it; power-on: g is
/// referred to its mean over the B0 window, the rule's own form, and `offset` is the run's
/// turn-on bias).
inline void DrawBias(sim::Run& run, const PolySpec& spec, const Eigen::VectorXd& beta, double offset, const Ar1& noise,
                     boost::random::mt19937_64& rng) {
  boost::random::normal_distribution<double> normal;
  PolyRegressors g(spec);
  const auto channels = spec.Channels();
  std::vector<const std::vector<double>*> columns;
  for (const auto& ch : channels) columns.push_back(&run.Column(ch));
  auto& b = run.columns[static_cast<size_t>(run.Find("bias_dph"))];
  Eigen::VectorXd row(beta.size());
  std::vector<double> T(channels.size()), model(run.size());
  double reference = 0.0;
  size_t in_window = 0;
  for (size_t k = 0; k < run.size(); ++k) {
    for (size_t c = 0; c < channels.size(); ++c) T[c] = (*columns[c])[k];
    g.Next(run.t_s[k], T.data(), row.data());
    model[k] = beta.dot(row);
    if (spec.offset == OffsetRule::kPowerOn && run.t_s[k] < run.t_s.front() + spec.b0_window_s) {
      reference += model[k];
      ++in_window;
    }
  }
  if (in_window > 0) reference /= static_cast<double>(in_window);
  const double phi = noise.tau_samples > 0.0 ? std::exp(-1.0 / noise.tau_samples) : 0.0;
  double e = noise.sd * normal(rng);
  for (size_t k = 0; k < run.size(); ++k) {
    b[k] = offset + model[k] - reference + e;
    e = phi * e + std::sqrt(1.0 - phi * phi) * noise.sd * normal(rng);
  }
}

/// A PolySpec with the range and reference of `run`'s T1 (as the fit would set them).
inline PolySpec SpecFor(const std::vector<const sim::Run*>& runs, int order, OffsetRule offset, std::vector<PolyTerm> terms = {},
                        double reference = NAN) {
  PolySpec s;
  s.order = order;
  s.offset = offset;
  s.terms = std::move(terms);
  double lo = 1e300, hi = -1e300;
  for (const auto* r : runs)
    for (double T : r->Column("T1")) lo = std::min(lo, T), hi = std::max(hi, T);
  s.range_C = {lo, hi};
  s.reference_C = std::isnan(reference) ? 0.5 * (lo + hi) : reference;
  return s;
}

}  // namespace rlg::model
