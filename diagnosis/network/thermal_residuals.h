#pragma once
/// Thermal residuals of a prediction and the sums they are weighed by.
///
/// A residual is simulated - measured, per run, gyro sensor and counted fit block (°C). Each
/// channel s is weighed by its variance var_s (°C², ChannelVariances):
///     chi² = sum_runs sum_s sum_blocks e² / var_s
/// and scored on score-block means (ToScoreBlocks), unweighted:
///     score SSR = sum_runs sum_s sum_score_blocks mean(e)²    (°C²)
/// A candidate's in-sample evidence is generalised least squares on the fit blocks
/// (ThermalGlsGain): per channel, the innovations u = e_k - sum_i phi_i e_{k-i} of an AR noise
/// model, each run a segment (its first p values have none), and
///     gain = sum_s n_s ln(SSR_base,s / SSR_ext,s)      (n_s innovations of channel s)

#include <vector>

#include "diagnosis/network/prediction.h"
#include "diagnosis/statistics/ar_noise.h"
#include "diagnosis/network/problem.h"

namespace rlg::diagnosis {

/// Per run, per gyro sensor, per counted fit block (°C); a sensor a run lacks has none.
using ThermalResidualSet = std::vector<std::vector<std::vector<double>>>;

/// prediction - data on the runs `which` (the others stay empty).
ThermalResidualSet ThermalResiduals(const Problem& p, const std::vector<Prediction>& pred, const std::vector<int>& which);

/// Model m's: of its simulation of the sensors alone (Sampled::kSensors) on the runs `which`.
ThermalResidualSet ThermalResiduals(const Problem& p, const Model& m, const std::vector<int>& which);

/// a - b, run by run and channel by channel.
ThermalResidualSet Difference(ThermalResidualSet a, const ThermalResidualSet& b);

/// chi² above over the runs `which`.
double ThermalChi2(const ThermalResidualSet& res, const std::vector<int>& which, const std::vector<double>& channel_var);

/// The weights of the first calibration pass, before any residual is known: (10 mK)².
inline constexpr double kUnitChannelVar = 1e-4;

/// Per gyro sensor, the mean squared fit-block residual over the fit runs (°C²), floored at
/// (0.5 mK)²: a perfect model must not get infinite weight. A channel no fit run has keeps
/// kUnitChannelVar (it has no residual to weigh).
std::vector<double> ChannelVariances(const Problem& p, const ThermalResidualSet& res);

/// Sum of squared score-block means of one channel's fit-block residuals in run r (°C²); adds
/// their count to *n when given.
double ScoreSsr(const Problem& p, const std::vector<double>& residuals, int r, int* n = nullptr);

/// The highest AR order of a thermal channel's residual on its fit blocks: ten 10 s blocks
/// follow a misfit that decorrelates in minutes and the white noise above it, as
/// kMaxBiasArOrder does for the bias.
inline constexpr int kMaxThermalArOrder = 10;

/// Per channel (0..channels-1), the AR order of least AIC (FitAr, at most kMaxThermalArOrder)
/// of its fit-block residuals over the runs `which`, each run a segment: the order a thermal
/// search prewhitens every candidate's score with (0 for a channel none of them has).
std::vector<int> ThermalArOrders(const ThermalResidualSet& res, const std::vector<int>& which, size_t channels);

/// Per channel, the Yule-Walker AR model of order orders[s] (FitArOfOrder, °C) of its fit-block
/// residuals over the runs `which`, each run a segment; white of sigma 0 for a channel none of
/// them has.
std::vector<ArModel> ThermalNoiseModels(const ThermalResidualSet& res, const std::vector<int>& which,
                                        const std::vector<int>& orders);

/// The log-likelihood ratio of `ext` against `base` on the runs `which`, in information units
/// (2 ln L), feasible generalised least squares: per channel s, an AR model of order
/// orders[s] is fitted (FitArOfOrder) to ext's residuals, both residual sets are prewhitened by
/// it (ArInnovations, run by run) and the channel adds n_s ln(SSR_base / SSR_ext) over its n_s
/// innovations. The noise model is the extension's: one fitted to the base's residuals would
/// take a missing effect for slow noise. On white residuals it is the chi² difference in units
/// of the extension's variance; on a slow misfit (a nominal wrong within its uncertainty) that
/// a candidate follows only in part, it counts the innovations the candidate removes, not the
/// slow variance it borrows.
double ThermalGlsGain(const ThermalResidualSet& base, const ThermalResidualSet& ext, const std::vector<int>& which,
                      const std::vector<int>& orders);

/// ScoreSsr over the runs `which` and their channels (°C²): the held-out RMS of
/// docs/diagnosis.md comes from it, on the scale the bias uses too.
double ThermalScoreSsr(const Problem& p, const ThermalResidualSet& res, const std::vector<int>& which, int* n = nullptr);

}  // namespace rlg::diagnosis
