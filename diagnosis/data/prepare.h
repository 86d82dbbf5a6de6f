#pragma once
/// Part of stage 1 of a diagnosis (network/problem.h): the data prepared for calibration and scoring.
///
/// Contract: from a trace and a nominal gyro, each run becomes a PreparedRun that says which
/// columns are the gyro's sensors and its bias, what power its data-driven sources receive,
/// and how its samples are cut into blocks. Nothing here simulates or fits; every function is
/// pure (a PreparedRun points into the trace, which must outlive it).
///
/// Block layout, in whole samples of the run's median sample period dt (s):
///
///     fit block    = dt * max(1, round(fit_block_s / dt))                      [s]
///     score block  = fit block * max(1, round(score_block_s / fit block))      [s]
///
/// so with the defaults (10 s, 100 s): 10 s and 100 s at dt = 0.1 s and 1 s, 10 s and 100 s at
/// 10 s, 60 s and 120 s at 60 s (99 s at 3 s). Every residual is averaged over a fit block
/// (calibration, bias fits) and every score and held-out RMS over a score block.
///
/// Held-out split: runs named in DiagnoseOptions::fit_runs are fitted, the others scored; a
/// single run with none held out is cut in time (SplitInTime) into equal pieces, fitted on
/// the even ones and scored on the odd ones, both simulated from power-on.
///
/// Noise level: ScoreBlockNoise is the white noise of a score-block mean of the quietest
/// temperature channel (°C), from sample-to-sample differences; SolverForData turns it into
/// CVODE tolerances a tenth of it; PointNoise is the white noise of a sampled curve (its
/// units) from second differences, which a smooth curve's trend does not enter.

#include <algorithm>
#include <string>
#include <utility>
#include <vector>

#include "diagnosis/options.h"
#include "sim/ambient.h"
#include "sim/gyro.h"
#include "sim/solver_options.h"
#include "sim/trace.h"

namespace rlg::diagnosis {

/// A run, or some stretches of one: residuals count only for blocks starting in one of
/// `windows` ([from, to) in s; empty: the whole run), while the simulation always starts at
/// the run's power-on.
struct PreparedRun {
  const sim::Run* run = nullptr;
  std::string label;  ///< the run id, and which stretches when it is some
  std::vector<std::pair<double, double>> windows;
  /// The prepared run whose nuisances (unlogged ambient, per-run gains) apply: itself, or for
  /// the held-out stretches of a single run, its fitted stretches.
  int nuisance = -1;
  bool Counts(double t) const {
    return windows.empty() ||
           std::any_of(windows.begin(), windows.end(), [t](const auto& w) { return t >= w.first && t < w.second; });
  }
  bool ambient_known = false;
  sim::Profile ambient = sim::Profile::Constant(0.0);  ///< logged ambient: through ~1 s means (MakeProblem)
  /// Per source: its power (W) over the run, from the data's P_<source>_W when logged (a
  /// data-driven source must be), else the gyro's constant power_W.
  std::vector<sim::Profile> data_power;
  std::vector<bool> power_logged;        ///< per source: P_<source>_W is in the run
  std::vector<int> sensor_col;           ///< per gyro sensor: column in run, or -1
  int bias_col = -1;
  /// Block layout in whole samples (BlockLayout): the run's median sample period, its fit
  /// blocks, and how many fit blocks make one score block.
  double sample_period_s = 0.0;
  double fit_block_s = 0.0;
  int fit_blocks_per_score = 1;
  double score_block_s() const { return fit_block_s * fit_blocks_per_score; }
};

/// Fit and score blocks of a run in whole samples, as close to the options' lengths as the
/// sample period allows: fit blocks of round(fit_block_s / dt) >= 1 samples, score blocks of
/// round(score_block_s / fit block) >= 1 fit blocks. Counting blocks instead of time made
/// "100 s means" 600 s means on 60 s data; on 3 s data they are 99 s, on 60 s
/// 120 s, and the report says so. Precondition: p.run is set and has two or more samples
/// (SamplePeriod throws InputError otherwise).
void BlockLayout(PreparedRun& p, const DiagnoseOptions& o);

/// One PreparedRun per run of `data`, in its order, each its own nuisance. InputError for a
/// run of fewer than 20 samples, one with none of the gyro's temperature channels, or one
/// without the P_<name>_W column of a data-driven source. The logged ambient curve is left
/// to the caller (it needs the noise level of all runs).
std::vector<PreparedRun> Prepare(const sim::Trace& data, const sim::GyroConfig& gyro, const DiagnoseOptions& o);

/// A single run cut in time into `pieces` (at least 2) equal pieces: `fit` holds the even
/// pieces, `held` the odd ones, both with the whole run's nuisances (index 0); `note` says
/// which stretches are which ("one run, held out in time: fitted on t = 0-150, 299-449 s,
/// scored on ..."). The last piece is open-ended so that no sample falls outside.
struct SplitRun {
  PreparedRun fit, held;
  std::string note;
};
SplitRun SplitInTime(const PreparedRun& whole, int pieces);

/// Consecutive blocks of samples [first, second), each starting at a sample and holding the
/// samples within block_s of it (half a microsecond of slack for round-off in the times). A
/// last block with fewer than half of a full block's round(block_s / sample_period_s) samples
/// is left out: a run of 9000 s at 0.1 s ends with one sample at t = 9000 s, whose bias noise
/// is 10x a full block's, and the step detector reported it as a 0.37 °/h step.
std::vector<std::pair<size_t, size_t>> Blocks(const std::vector<double>& t, double block_s, double sample_period_s);

/// Mean of v over the samples [b.first, b.second). Precondition: b is not empty.
double BlockMean(const std::vector<double>& v, std::pair<size_t, size_t> b);

/// Noise of a score-block mean of the quietest temperature channel (°C): per channel, the
/// sample sd from sample-to-sample differences, s = sqrt(sum (v_k - v_k-1)² / (n - 1) / 2)
/// (white noise of sd s has differences of sd s sqrt(2)), over sqrt(samples per score block);
/// the smallest over runs and channels. Infinity without a noisy channel (noise-free data).
double ScoreBlockNoise(const std::vector<PreparedRun>& runs);

/// Noise of the values of a sampled curve (t, v), robustly from their second differences: for
/// white noise of sd s each difference has sd s sqrt(6), and the median absolute difference is
/// 0.6745 of an sd; a smooth curve's own second differences are far smaller, and its corners
/// are few enough not to move the median. Exact zeros are left out: a simulated or set-point
/// ambient is exactly constant on its dwells, which have no noise to measure, and they made
/// the median 0 while the ramps carried the column's rounding. 0 without a nonzero difference
/// (a straight line).
double PointNoise(const std::vector<std::pair<double, double>>& pts);

/// Noise of a sampled curve's values that is there at (nearly) every point: from the median of
/// all absolute second differences, zeros included, sd = median / 0.6745 / sqrt(6). A curve
/// that is exact between rare corners or roundings (a simulated or set-point ambient) gives 0:
/// more than half its second differences are zero to round-off (below 1e-9 of the curve's
/// largest magnitude), so what PointNoise measures there is corners or rounding, not noise.
double NoiseAtEveryPoint(const std::vector<std::pair<double, double>>& pts);

/// The curve through which a logged ambient drives the model, from its ~1 s means `pts`
/// (times increasing, at least two), given the score-block noise of the temperatures (°C,
/// possibly infinite).
///
/// Exact records (NoiseAtEveryPoint = 0) keep their points where the curve moves, as
/// SimplifyPolyline does with a tolerance of max(0.1 noise, min(3 PointNoise, noise)) (see the
/// MakeProblem). A noisy record (a chamber sensor with sd s per point) is not interpolated: a curve
/// through noisy points feeds the noise into every node the ambient reaches, and 2 mK of it on
/// the reference generator's ambient left ~0.7 mK of systematic residual on the block, which a
/// thermal candidate then took up on every dataset (tests/reference/survey-baseline.md). It is
/// smoothed instead by a continuous piecewise-linear least-squares fit: knots where the chord
/// leaves the points by 5 s (SimplifyPolyline; a chord between two noisy points is itself off
/// by up to ~1.4 s, so at 3 s the chords ended on noise alone every ~12 points), refined where the fit's residual, averaged
/// over 8, 32, 128 or 512 consecutive points, is more than 4 standard errors from zero (4 s /
/// sqrt(m): a structure the knots miss is found once it stands out from its own noise, and
/// about one window in 16,000 of pure noise adds a harmless extra knot). What stays is the
/// knot values' own averaging noise and a structure below 4 s / sqrt(512) = 0.18 s over 512
/// points. `start_sd`, when given: the standard error of the curve's first value (s times the
/// square root of the first knot's diagonal of (A'WA)^-1; 0 for an exact record). `end_weight`:
/// the first and last points' weight against the others' 1 (LoggedAmbient's raw end readings
/// among block means of sub-second samples: 1 / the samples a block holds); when it is not 1
/// (and there are 5 points or more), s, the knots and the refinement come from the points
/// between the ends, which take the first and last knots' times.
sim::Profile LoggedAmbientCurve(const std::vector<std::pair<double, double>>& pts, double score_block_noise,
                                double* start_sd = nullptr, double end_weight = 1.0);

/// Samples k (>= 1) where a logged input jumps: its difference d_k = v_k - v_(k-1) is more than
/// 10 times both neighbouring differences, more than 10 times the noise of a difference
/// (sqrt(2) NoiseAtEveryPoint of the samples) and more than `min_jump` (a column's last digit
/// flipping on a dwell is no step worth a breakpoint). A ramp, however coarsely sampled, moves alike
/// from one sample to the next (a corner halves or doubles a difference at most); a step set
/// between two samples moves in one difference alone. What the input did between v_(k-1) and
/// v_k is not in the record: it is taken to change at t_k, the sample that first shows it,
/// as the simulator's steps do (they take their new value at their own time) and as logged
/// powers are read (Profile::Steps). A curve through the two samples instead fed the
/// network the mean of old and new over the interval: for a 20 °C step of the ambient at
/// 1 s samples, 10 °C s into the default gyro's cabinet (8 W/K to ambient, 2500 J/K), 32 mK,
/// and the calibration of the worked example then missed T3 by 5-11x its noise on both runs.
/// Real data that changed anywhere in the interval are off by at most that interval.
std::vector<size_t> InputJumps(const std::vector<double>& v, double min_jump);

/// The ambient curve of one run's logged column v at times t: cut at InputJumps into stretches,
/// each through its means over blocks of max(1 s, one sample) (LoggedAmbientCurve), held at its
/// last value until the next stretch starts, a millionth of the sample period before it. Jumps
/// below the score-block noise (1 mK on noise-free data) are not cut at: over one sample they
/// move no temperature by more than a fraction of it. `start_sd`, when given: the standard
/// error of the curve's value at the first sample (LoggedAmbientCurve's of the first stretch;
/// a stretch of one reading has that reading's noise).
sim::Profile LoggedAmbient(const std::vector<double>& t, const std::vector<double>& v, double sample_period_s,
                           double score_block_noise, double* start_sd = nullptr);

/// CVODE tolerances matched to the data (used by nonlinear candidates; linear networks are
/// propagated exactly). The integration error must stay well below what a score can see: a
/// tenth of the noise of a score-block mean. CVODE restarted every second for an hour drifted
/// from the exact solution by 1.5 mK at tol 1e-6, 0.14 mK at 1e-8, 17 uK at 1e-9 and 2.8 uK
/// at 1e-10 (tests/sim/test_thermal_network.cpp): at most 1.5e4 x tol °C below 1e-8, hence
/// rtol = atol = clamp(noise / 10 / 1.5e4, 1e-10, 1e-6), and 1e-9 for infinite noise.
sim::SolverOptions SolverForData(double score_block_noise);

}  // namespace rlg::diagnosis
