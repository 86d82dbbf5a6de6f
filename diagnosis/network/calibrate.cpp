#include "diagnosis/network/calibrate.h"

#include <Eigen/QR>
#include <algorithm>
#include <cmath>
#include <fmt/format.h>
#include <limits>

#include "diagnosis/network/fit_thermal.h"
#include "diagnosis/network/free.h"
#include "diagnosis/network/knob_prior.h"
#include "diagnosis/network/prediction.h"
#include "diagnosis/network/thermal_residuals.h"
#include "diagnosis/statistics/unexplained.h"
#include "sim/errors.h"

namespace rlg::diagnosis {

namespace {

/// Some channel's residual variance above twice the white noise's variance of a fit block (or
/// of the variances' floor): the fit misses the data by well over their noise.
bool MissesTheData(const Problem& p, const Calibration& c) {
  bool misses = false;
  for (size_t s = 0; s < p.nominal.sensors.size(); ++s) {
    double white = 0.0;
    int runs = 0;
    for (int r : p.fit) {
      if (p.runs[r].sensor_col[s] < 0 || p.fit_blocks[r].empty()) continue;
      const auto [from, to] = p.fit_blocks[r].front();
      white += std::pow(WhiteNoiseSd(p.runs[r].run->columns[static_cast<size_t>(p.runs[r].sensor_col[s])]), 2) /
               static_cast<double>(to - from);
      ++runs;
    }
    // Twice the white noise's variance of a fit block, or of the variances' floor.
    if (runs > 0) misses = misses || c.channel_var[s] > 2.0 * std::max(white / runs, 2.5e-7);
  }
  return misses;
}

/// `start` with every heat capacity times f.
Model ScaleCapacities(const Problem& p, const Model& start, double f) {
  Model m = start;
  for (size_t q = 0; q < p.knobs.size(); ++q)
    if (p.knobs[q].kind == KnobKind::kHeatCapacity) m.base[q] *= f;
  return m;
}

/// The factor 2^(i/6), i = -6..6, on every heat capacity of `start` with the least unweighted
/// chi² on the fit runs; 1 when none beats it.
double BestCapacityScale(const Problem& p, const Model& start) {
  const std::vector<double> unit(p.nominal.sensors.size(), kUnitChannelVar);
  double best_f = 1.0, best_chi2 = std::numeric_limits<double>::infinity();
  for (int i = -6; i <= 6; ++i) {
    const double f = std::pow(2.0, i / 6.0);
    const Model trial = ScaleCapacities(p, start, f);
    try {
      const double chi2 = ThermalChi2(ThermalResiduals(p, trial, p.fit), p.fit, unit);
      if (chi2 < best_chi2) best_chi2 = chi2, best_f = f;
    } catch (const std::exception&) {  // a factor the simulation cannot run is no start
    }
  }
  return best_f;
}

}  // namespace

Calibration Calibrate(const Problem& p, const Model& start) {
  Calibration out = CalibrateOnce(p, start);
  if (!KnobsInConflict(p, out.model)) return out;
  // A conflict is evidence of missing structure, or, where the fit also misses the data by
  // well over their noise, of a local minimum. Only then: a missing mass at 4x the noise
  // bent the knobs into conflict with a fit at the noise (residual variance 1.1x the white
  // noise's), and a restart took more of the mass into the capacities than the search could
  // then find; the heavy nominal's wrong minima missed by ~4x in variance.
  if (!MissesTheData(p, out)) return out;
  // The heat capacities' common scale (every time constant at once, which a nominal can miss
  // by more than its prior says) is searched on a grid of factors 0.5-2 by the unweighted chi²
  // of the fit runs, and the fit repeated from the best. The likelier of the two calibrations
  // is kept.
  const double best_f = BestCapacityScale(p, start);
  if (best_f == 1.0) return out;
  try {
    Calibration again = CalibrateOnce(p, ScaleCapacities(p, start, best_f));
    if (CalibrationDeviance(p, again) < CalibrationDeviance(p, out)) {
      again.summary.start_capacity_scale = best_f;
      return again;
    }
  } catch (const NumericalError&) {  // the nominal's fit stands
  }
  return out;
}

double CalibrationDeviance(const Problem& p, const Calibration& c) {
  const auto res = ThermalResiduals(p, c.model, p.fit);
  double d = ThermalChi2(res, p.fit, c.channel_var) + KnobPriorCost(p, c.model);
  for (size_t s = 0; s < p.nominal.sensors.size(); ++s) {
    size_t n = 0;
    for (int r : p.fit) n += res[r][s].size();
    d += static_cast<double>(n) * std::log(c.channel_var[s]);
  }
  return d;
}

Calibration CalibrateOnce(const Problem& p, const Model& start) {
  // Channel variances come from a first pass (unit weights), then the fit is repeated with
  // them; the held-out runs' nuisances follow with the knobs fixed.
  const CalibrationOptions& co = p.options.calibration;
  Calibration out;
  const std::vector<int> all = p.All();
  const ThermalFit first = FitThermal(p, start, BaselineFree(p, p.fit), p.fit,
                                      std::vector<double>(p.nominal.sensors.size(), kUnitChannelVar), co.max_iterations);
  out.channel_var = ChannelVariances(p, ThermalResiduals(p, first.model, all));
  const ThermalFit second =
      FitThermal(p, first.model, BaselineFree(p, p.fit), p.fit, out.channel_var, co.max_iterations, true);
  if (!second.summary.usable) {
    throw NumericalError(fmt::format("diagnose: {}the calibration of the nominal gyro to the data failed (the simulation "
                                     "failed at the start point); check that the gyro file describes this data",
                                     p.runs.front().run->source.empty() ? "" : p.runs.front().run->source + ": "));
  }
  const ThermalFit nuisance =
      FitThermal(p, second.model, AmbientFree(p, p.held), p.held, out.channel_var, co.nuisance_max_iterations);
  out.model = nuisance.model;
  CalibrationSummary& s = out.summary;
  // A held-out run whose nuisance fit failed keeps its start ambient; its held-out RMS shows it.
  s.usable = second.summary.usable;
  s.initial_cost = second.summary.initial_cost;
  s.final_cost = second.summary.final_cost;
  s.iterations = first.summary.iterations + second.summary.iterations + nuisance.summary.iterations;
  s.prior_sd = p.nominal.calibration_uncertainty;
  const auto k = static_cast<Eigen::Index>(p.knobs.size());
  s.covariance = second.jtj.completeOrthogonalDecomposition().pseudoInverse().topLeftCorner(k, k);
  for (size_t i = 0; i < p.knobs.size(); ++i) {
    const double nominal = p.knobs[i].nominal, calibrated = out.model.base[i];
    const auto ii = static_cast<Eigen::Index>(i);
    s.knobs.push_back({p.knobs[i].name, nominal, calibrated, KnobShiftSigma(p, out.model, i),
                       std::sqrt(std::max(0.0, s.covariance(ii, ii))), p.knobs[i].Label()});
  }
  for (int r : all)
    if (p.runs[r].nuisance == r && p.runs[r].ambient_known && p.start_sd[r] > 0.0)
      s.starts.push_back({p.runs[r].label, out.model.start[r], p.start_sd[r]});
  return out;
}

}  // namespace rlg::diagnosis
