#pragma once
/// Thermal residuals of a prediction and the sums they are weighed by.
///
/// A residual is simulated - measured, per run, gyro sensor and counted fit block (°C). Each
/// channel s is weighed by its variance var_s (°C², ChannelVariances):
///     chi² = sum_runs sum_s sum_blocks e² / var_s
/// and scored on score-block means (ToScoreBlocks), unweighted:
///     score SSR = sum_runs sum_s sum_score_blocks mean(e)²    (°C²)

#include <vector>

#include "diagnosis/network/prediction.h"
#include "diagnosis/network/problem.h"

namespace rlg::diagnosis {

/// Per run, per gyro sensor, per counted fit block (°C); a sensor a run lacks has none.
using ThermalResidualSet = std::vector<std::vector<std::vector<double>>>;

/// prediction - data on the runs `which` (the others stay empty).
ThermalResidualSet ThermalResiduals(const Problem& p, const std::vector<Prediction>& pred, const std::vector<int>& which);

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

/// ScoreSsr over the runs `which` and their channels (°C²): the held-out RMS of
/// docs/diagnosis.md comes from it, on the scale the bias uses too.
double ThermalScoreSsr(const Problem& p, const ThermalResidualSet& res, const std::vector<int>& which, int* n = nullptr);

}  // namespace rlg::diagnosis
