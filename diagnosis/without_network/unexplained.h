#pragma once
/// Stage 7 of a diagnosis without a thermal network: what the final model still misses in the
/// bias, where, and whether it moves with the temperature.
///
/// Per scored unit, the final model's held-out fit-block residual is weighed as statistics/unexplained.h
/// weighs a temperature channel: channel "bias_dph", its noise s the white noise of the run's
/// bias samples (WhiteNoiseSd) over sqrt(samples per score block), and as covariates the
/// bias-temperature channel T ("T1", °C), its rate ("dT1/dt", °C/min) and whether it heats or
/// cools ("heating T1": +1 where the block means' rate is positive, -1 where negative, 0 where
/// it is zero). FindUnexplained keeps a unit whose score-block RMS exceeds 1.5 s and whose
/// residual is not white, with the stretch where it stands out most and its correlations.
///
/// A gyro's bias is seldom white over minutes (bias instability), so those two tests alone
/// would call pure noise unexplained. A unit is unexplained only when its residual also moves
/// with the temperature more than noise does: its largest |r| with the three covariates must
/// exceed the largest any scored unit's residual reaches on all of 5 R null replicates (R =
/// options.null_replicates), which noise alone would do about once in 5 R + 1 datasets were the
/// noise model exact. The replicates (without_network/null.h, substream 1) are
/// the final model's fit plus AR noise of the residuals of the full model, the baseline with
/// every candidate of the first search at once: the noise model must not be fitted to the very
/// misfit under test (the baseline's residuals carry it, and AR noise as slow as a hysteresis
/// loop correlates with the temperature as well as the loop does), while every candidate
/// together takes up no more than an overfit of a few columns on noise alone, which makes the
/// replicates a little quieter than the noise: hence 5 R of them, not R.

#include <map>
#include <string>
#include <vector>

#include "diagnosis/without_network/problem.h"
#include "diagnosis/statistics/unexplained.h"

namespace rlg::diagnosis {

struct MeasuredUnexplained {
  std::vector<Unexplained> entries;  ///< the units left unexplained, in unit order
  double data_correlation = 0.0;     ///< the data's largest |r| with the covariates
  std::string data_covariate;        ///< the covariate it is with; empty when none is defined
  double data_r = 0.0;               ///< that correlation with its sign
  double null_correlation = 0.0;     ///< the replicates' largest (0 without replicates)
  int replicates = 0;                ///< how many were drawn
  /// How much is left, whether or not it moves with the temperature: the final model's held-out
  /// residual, the RMS of its score-block means over every scored unit (°/h, the report's
  /// extended bias_rms_dph), and the white noise of such a mean, pooled as a root mean square
  /// over the same score blocks (each unit's s above).
  double rms_dph = 0.0, noise_dph = 0.0;
};

/// The covariates above of unit u, at its counted blocks.
std::map<std::string, std::vector<double>> MeasuredCovariates(const MeasuredProblem& p, int u);

/// Stage 7 on the regression of `model_columns` (the final model), its null replicates' noise
/// from the residuals of `full_columns` (5 options.null_replicates of them; with none, every unit
/// that FindUnexplained keeps).
MeasuredUnexplained FindMeasuredUnexplained(const MeasuredProblem& p, const std::vector<RunColumns>& model_columns,
                                            const std::vector<RunColumns>& full_columns, const UnexplainedOptions& o);

}  // namespace rlg::diagnosis
