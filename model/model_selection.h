#pragma once
/// Scores inside the training data, and `auto`: the polynomial model (model/poly_model.h) whose
/// order, offset rule and terms, products among them, are chosen by a stepwise search of a
/// library of terms, scored by cross-validation from sufficient statistics (model/gram_cv.h).
///
/// Folds (SelectionFolds). With min_runs_as_folds (3) or more training runs, leave one run out:
/// fold r holds out run r whole, so every score is of a power-on the fit has not seen, as in
/// service (a temperature range, a ramp, an extrapolation). With fewer, each run is cut into
/// `folds` (8) contiguous pieces of equal sample counts and fold k holds out piece k of every
/// run (BlockFolds): a held-out piece is a stretch of time, so the slow noise and misfit of
/// thermal data cannot leak into it from its neighbours except at its two ends. A model's
/// regressors and its compensator run over the whole run from power-on, so a held-out sample
/// sees only what came before it, as in use.
///
/// BlockedCv, the score of any fitted compensator: the RMS (°/h) of the compensated bias over
/// the held-out samples of every fold. A model that holds its polynomial at the fitted range's
/// edge is scored on the held-out samples inside the range its fold was fitted on (beyond it
/// every such polynomial is held alike, and on one chamber cycle, whose pieces hold its
/// extremes, that error, 6.4 °/h RMS on 0.05 °/h of noise, drowned every difference between
/// models); a model that extrapolates is scored on every held-out sample.
///
/// auto. The library, for the model's channel T and each other channel Tj that every run has:
///   order       T^2 .. T^5 (T^k needs T^(k-1); T itself is always in)
///   rate        rate, T*rate(T)
///   hysteresis  the play term at 6 widths over [span/200, span/2] (one at most; only when the
///               data heat and cool by a tenth of the span), its width refitted by profile
///   lag         the lag term at 6 time constants over [2 sample periods, half the longest run]
///               (one at most), refitted by profile
///   per Tj      gradient:Tj, T*(Tj-T), (Tj-T)^2, T^2*(Tj-T), rate(Tj-T)
///   per Tj, Tk  (Tj-T)*(Tk-T)
/// or the candidate terms given. A product needs the terms it is made from that the library
/// holds (T*(Tj-T) needs gradient:Tj; T^2*(Tj-T) needs T*(Tj-T) and order 2): a move adds a
/// term with whatever it needs, so a product that helps only with its parent is found in one
/// step. For each offset rule allowed (fitted; power_on when every run spans the B0 window):
///   1. forward: from order 1, the move of lowest score is taken, whether or not it helps,
///      until the score has not improved on the best for `patience` (3) moves in a row, or
///      no move is left (max_parameters): the search does not stop where one term fails to help;
///   2. stepwise: from the best model of the forward path, the removal (of a term nothing else
///      needs) of lowest score is taken while it lowers the score, then an addition while one
///      does, repeated until neither does;
///   3. backward to order 1: the removal of lowest score at each step, whatever it does, so that
///      the nested models between the lowest score and order 1 are all scored.
/// Every model visited is scored and kept. The selection (the parsimony rule, after the search):
/// of every model visited under either offset, in the order of fewer parameters (coefficients,
/// widths, time constants, and the offset: a fitted c0 or each run's measured B0 alike), then
/// fewer terms beyond the polynomial, then the lower score of the held-out 100 s means (Table
/// 2's time), then the lower score, the first
/// that the model of lowest score does not beat (SelectionBeats). b beats a when its mean
/// square is lower by at least min_gain (10 %) and the K folds say so at `confidence` (95 %):
/// the fold-by-fold log ratio of their held-out sums of squares, log(SSE_a,k / SSE_b,k), is
/// positive by a one-sided paired t-test, or b is lower in enough folds by a one-sided sign test
/// (all 5 of 5, 6 of 6, 7 of 8, 11 of 14), or its mean square is at most a quarter (kClearlyLower),
/// or, with whole runs held out, the sum over folds of SSE_a,k - SSE_b,k exceeds one standard
/// error (sqrt(K) times their sd; Hastie, Tibshirani and Friedman's one-standard-error rule).
/// The ratio, not the difference: a term that matters on ramps alone lowers the ramps' folds by
/// orders of magnitude and leaves the soaks' alone, and the differences' spread would hide it;
/// the sign test and the quarter, because over five runs a soak that a simpler model happens to
/// predict as well (one fold of five) hid from both tests a model 4.7 times better in mean
/// square (the part-to-part spread of the default gyro, three soaks and two ramps); the
/// differences, because nine soaks and two ramps hid a quadratic that matters on the ramps
/// alone (0.08 °/h left on them) from the tests of ratios and signs. Runs held out whole are
/// independent power-ons, each with its own noise, so the spread of their differences is an
/// honest error of the sum; the pieces of one run share its slow noise, and there the
/// one-standard-error rule took a term in 5 of 20 datasets made without one. Why a test
/// and a margin both: the
/// lowest of a few hundred scores is optimistic, and with the spread alone (one standard error)
/// a product the bias did not hold was taken in 11 of 20 datasets.
/// Why 100 s means between models of equal size: what separates them is often slow (a fitted
/// offset or B0, whose 120 s mean carries 0.006 °/h of error into every sample of the default
/// gyro's runs: a hundredth of its 1 s samples' mean square, which the samples' score cannot
/// see), and the 100 s stability and the run mean are what a compensated gyro is judged on.
/// The selected model is then fitted on every sample (FitPoly, widths and time constants by
/// profile) and extrapolates beyond its range: whole runs held out scored it there.
/// Measured (tests/model/test_model_selection.cpp, 60 datasets each): a hysteresis loop twice
/// the noise's sd on one chamber cycle taken in 55 of 60, a term added to a cubic without one in
/// 3 of 60; the temperature x gradient product of the Langmuir term taken from soaks and ramps
/// in 60 of 60 and never where the bias had none.

#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "model/b0_window.h"
#include "model/gram_cv.h"
#include "model/linear_compensator.h"
#include "model/linear_fit.h"
#include "model/poly_fit.h"
#include "model/poly_model.h"
#include "sim/trace.h"

namespace rlg::model {

/// One mask per fold: piece k of every run held out (0), the rest used (1). InputError when a
/// run has fewer than 2 samples per fold.
std::vector<RowMask> BlockFolds(const std::vector<const sim::Run*>& runs, int folds);
/// One mask per run: run r held out whole, the others used.
std::vector<RowMask> RunFolds(const std::vector<const sim::Run*>& runs);
/// RunFolds with min_runs_as_folds runs or more, else BlockFolds (header).
std::vector<RowMask> SelectionFolds(const std::vector<const sim::Run*>& runs, int folds, int min_runs_as_folds);

/// A fit on the samples a mask keeps, as the compensator it makes.
using FoldFit = std::function<LinearCompensator(const RowMask& training)>;

/// The score of a model fitted by `fit`; a fit's NumericalError or InputError passes through.
CvScore BlockedCv(const std::vector<const sim::Run*>& runs, const std::vector<RowMask>& folds, const FoldFit& fit,
                  const std::string& bias_column = "bias_dph");
/// Its RMS alone.
double BlockedCvRms(const std::vector<const sim::Run*>& runs, const std::vector<RowMask>& folds, const FoldFit& fit,
                    const std::string& bias_column = "bias_dph");

/// The same for a polynomial model fitted with `options` (errors are not computed per fold).
CvScore PolyCv(const std::vector<const sim::Run*>& runs, const std::vector<RowMask>& folds, PolyFitOptions options);
double PolyCvRms(const std::vector<const sim::Run*>& runs, const std::vector<RowMask>& folds, PolyFitOptions options);

struct AutoOptions {
  std::string channel = "T1";
  std::optional<OffsetRule> offset;    ///< nullopt: each allowed (header)
  std::optional<double> reference_C;   ///< as PolyFitOptions
  double b0_window_s = kB0Window_s;
  double rate_tau_s = 0.0;
  /// The library (PolyFitOptions::terms spelling, products included); empty: the header's.
  std::vector<std::string> candidate_terms;
  int folds = 8;              ///< pieces per run when the runs are too few to be the folds
  int min_runs_as_folds = 3;  ///< from this many runs on, leave one run out
  int patience = 3;           ///< forward moves without a new best before the forward search stops
  int max_parameters = 24;    ///< no model larger than this is visited
  /// The selection's test: the one-sided confidence at which the lowest score beats a model.
  double confidence = 0.95;
  /// The selection's margin (header), and that of Beats and SmallestUnbeatenOrder (the
  /// diagnosis's baseline order rule).
  double min_gain = 0.10;
  LinearFitOptions linear;
  ProfileOptions profile;
  bool IsValid(std::string* error) const;
};

/// [est] A mean square at most this fraction of another's beats it whatever the folds' spread
/// (an RMS at most half): in the selection tests spurious terms lowered the mean square of one
/// chamber cycle under AR(1) noise by up to 30 % and once by half, while the model the
/// part-to-part spread's three soaks and two ramps needed lowered it 22-fold.
inline constexpr double kClearlyLower = 0.25;

/// The selection's test (header): b beats a when its mean square is lower by at least
/// min_gain, and either it is at most kClearlyLower of a's, or the folds say so: at
/// `confidence` by the paired t-test of the log ratios log(SSE_a,k / SSE_b,k) or by the sign
/// test of how many folds b has the lower, or, with `independent_folds` (whole runs held out),
/// by the sum of the differences SSE_a,k - SSE_b,k beyond one standard error.
bool SelectionBeats(const CvScore& b, const CvScore& a, double min_gain, double confidence, bool independent_folds);

/// auto's test of one score against another: b beats a when its mean square is lower by at
/// least min_gain overall and lower in at least three quarters of the folds.
bool Beats(const CvScore& b, const CvScore& a, double min_gain);

/// auto's order rule (steps 1 and 3): of the scores of orders 1..5 (by_order[k] is order k + 1;
/// an order that could not be fitted has an infinite rms), the smallest order that no higher
/// order beats; 0 when none could be fitted.
int SmallestUnbeatenOrder(const std::vector<CvScore>& by_order, double min_gain);

/// The stopping rule in words, as the coefficient file's selection record states it.
std::string AutoRule(const AutoOptions& options);

/// auto on `runs`: the selected model fitted on every sample (preset "auto", extrapolating), its
/// selection record attached: the path of moves with their scores, and every model visited.
/// InputError for invalid options or data; NumericalError when not even order 1 can be fitted.
PolyModel FitAuto(const std::vector<const sim::Run*>& runs, const AutoOptions& options);

/// The options that refit the selected model (its channel, order, offset, reference rule, terms
/// and extrapolation): what `fit --model poly` would be told to reproduce it.
PolyFitOptions OptionsOf(const PolyModel& model, const AutoOptions& options);

}  // namespace rlg::model
