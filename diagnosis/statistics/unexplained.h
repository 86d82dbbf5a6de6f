#pragma once
/// Stage 7 of a diagnosis (docs/diagnosis.md, `unexplained`): what the final
/// model still misses. A diagnosis that ends with `none`, or with a cause, over residuals many
/// times the noise must say so, with where and with what they move, instead of a bare answer.
///
/// Per temperature channel and run, from the extended model's residuals (measured - simulated,
/// fit-block means):
///     rms_over_noise = RMS(score-block means of the residual) / s,
/// s the sd of a score-block mean of the channel's white noise, WhiteNoiseSd of the run's own
/// samples over sqrt(samples per score block). The channel is unexplained in that run when
///     rms_over_noise > min_rms_over_noise (1.5: the residual's variance 2.25 times the noise's;
///     pure noise over 20 or more score blocks stays below 1.5 with probability above 0.999,
///     and on the reference generator's null cases the largest of 12 channel-runs was 1.3) and
///     the fit-block residuals are not white (Ljung-Box p below max_ljung_box_p over 10 lags).
/// Where: the stretch of consecutive score blocks with the largest sum of (mean / s)² - 2. With what: the Pearson
/// correlation of the fit-block residual with each covariate (the channel's measured value,
/// its rate, a logged ambient, logged powers).
///
/// The bias is left out: its residual carries bias instability, whose level the null bootstrap
/// (NullBootstrap) already weighs against every bias candidate. Pure: no simulation.

#include <map>
#include <string>
#include <utility>
#include <vector>

namespace rlg::diagnosis {

/// One channel of one run, as the engine hands it over.
struct ChannelResidual {
  std::string run;      ///< the run (or held-out stretches) label
  std::string channel;  ///< "T1"
  std::vector<double> t_s;       ///< fit-block mid-times
  std::vector<double> residual;  ///< measured - simulated, per fit block (channel units)
  /// Covariate name ("T1", "dT1/dt", "T_amb", "P_discharge_W") -> its fit-block means.
  std::map<std::string, std::vector<double>> covariates;
  double score_block_noise = 0.0;  ///< s above; 0 or less: noise-free, never unexplained
  int fit_blocks_per_score = 1;
};

struct UnexplainedOptions {
  double min_rms_over_noise = 1.5;
  double max_ljung_box_p = 1e-3;
  /// False with a reason when min_rms_over_noise is below 1 or max_ljung_box_p is outside (0, 1].
  bool IsValid(std::string* error) const;
};

struct Unexplained {
  std::string channel;
  std::string run;
  double rms_over_noise = 0.0;
  double noise = 0.0;  ///< s (channel units)
  double ljung_box_p = 1.0;
  std::pair<double, double> t_s{0.0, 0.0};  ///< mid-times of the stretch's first and last fit blocks
  std::map<std::string, double> correlates_with;  ///< covariate -> Pearson r in [-1, 1]
};

/// The entries above, in the order of `channels`. A covariate that is constant over the run
/// (a dwell's ambient) or of another length is left out of correlates_with.
std::vector<Unexplained> FindUnexplained(const std::vector<ChannelResidual>& channels, const UnexplainedOptions& options);

/// White-noise sd of a channel's samples from its fourth differences
/// d_k = v_k+2 - 4 v_k+1 + 6 v_k - 4 v_k-1 + v_k-2 (a cubic has none; white noise of sd s gives
/// var d = (1 + 16 + 36 + 16 + 1) s² = 70 s²): the mean square of the smallest 90 % corrected for
/// the cut (a normal variable's square averages 0.6230 of its variance below its 95th absolute
/// percentile), then of those within 3 sd of it, corrected likewise (0.97334), until the kept set
/// holds. Fourth, not second, differences and a clip that adapts to what the input bends: a
/// thermal response's curvature between samples is no noise. At 60 s samples second differences
/// (the 98 % kept) read a housing's 5-minute step response as 13-45 mK of noise where the
/// sensor's was 2 mK (the reference generator's data): the thermal null bootstrap drew noise
/// 20x too large and accepted nothing at 10x the noise. On such a response (tests) this reads
/// 1.02x the noise at 60 s and 1.00x at 10 s and 1 s, where second differences read 49x and 1.25x.
/// Unlike a median of |d|, a mean square is not biased by a sensor's quantization (1 mK steps on
/// 2 mK noise moved the median by 10-20 %). 0 for fewer than 5 samples or an exact curve.
double WhiteNoiseSd(const std::vector<double>& v);

/// Pearson correlation of equal-length x and y; NaN when either is constant or they are shorter
/// than 3.
double Correlation(const std::vector<double>& x, const std::vector<double>& y);

/// One line for the text report: "T3 in run r1: residual RMS 3.1x the noise of its score-block
/// means (0.22 mK), not white (Ljung-Box p 2e-45), largest over t = 1800-6000 s; moves with
/// dT3/dt (r = +0.62), T3 (+0.31)" (covariates by |r|, largest first).
std::string UnexplainedText(const Unexplained& u);

}  // namespace rlg::diagnosis
