#pragma once
/// Scores inside the training data, and `auto`: the polynomial model (model/poly_model.h) whose
/// order, offset rule and extra terms are chosen by forward selection on that score.
///
/// Blocked cross-validation. Each training run is cut into `folds` (8) contiguous pieces of
/// equal sample counts; fold k holds out piece k of every run and fits on the rest. A model's
/// regressors and its compensator (model/linear_compensator.h) run over the whole run from
/// power-on, so a held-out sample sees only what came before it, as in use; only the held-out
/// samples are scored, and of those only the ones inside the temperature range the fold was
/// fitted on: beyond it every polynomial is held at the range's edge alike, and on one chamber
/// cycle, whose pieces hold its extremes, that error (6.4 °/h RMS on 0.05 °/h of noise in the
/// selection test's data) drowned every difference between the models. The score is the RMS
/// (°/h) of the compensated bias over those samples of every fold. Samples are never
/// interleaved between fit and score: a held-out piece is a stretch of time, so the slow noise
/// and misfit of thermal data cannot leak into it from its neighbours except at its two ends.
///
/// auto's rule. One score beats another when its mean square is lower by at least min_gain
/// (10 %) overall and lower in at least three quarters of the folds (Beats). For each offset
/// rule allowed (fitted; power_on when every run spans the B0 window):
///   1. order: the smallest of 1..5 that no higher order beats;
///   2. terms: each term not yet taken (rate, hysteresis, lag, a gradient to each other channel
///      the runs share) is added in turn; the one of lowest score is taken when it beats the
///      model without it; repeated until none does or none is left;
///   3. the order again, by step 1's rule, with the terms taken;
/// then, of the offsets' models, the one of fewest parameters (coefficients, widths, time
/// constants) that no other beats. A candidate whose fit fails on a fold (data that cannot
/// identify it there) is not taken; the record says why.
/// Why both conditions: the score of one AR(1)-noisy chamber cycle is noisy (about a hundred
/// independent stretches of noise): a term the data did not hold lowered its mean square by up
/// to 19 %, and with 5 folds and a 5 % margin alone a spurious term came in 4 times in 20. With
/// 8 folds, 10 % and three quarters of the folds: in 0 of 60 datasets made without an extra
/// term, while a hysteresis loop twice the noise's sd tall (it lowers the mean square by about
/// 80 %) was taken in 58 of 60 (tests/model/test_model_selection.cpp: 20 of each).

#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "model/linear_compensator.h"
#include "model/linear_fit.h"
#include "model/poly_fit.h"
#include "model/poly_model.h"
#include "sim/trace.h"

namespace rlg::model {

/// One mask per fold: piece k of every run held out (0), the rest used (1). InputError when a
/// run has fewer than 2 samples per fold.
std::vector<RowMask> BlockFolds(const std::vector<const sim::Run*>& runs, int folds);

/// A fit on the samples a mask keeps, as the compensator it makes.
using FoldFit = std::function<LinearCompensator(const RowMask& training)>;

/// The blocked cross-validation score (header), and each fold's mean square.
struct CvScore {
  double rms = 0.0;
  std::vector<double> fold_ms;
};
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
  std::optional<OffsetRule> offset;    ///< nullopt: each allowed (header, step 1)
  std::optional<double> reference_C;   ///< as PolyFitOptions
  double b0_window_s = 120.0;
  double rate_tau_s = 0.0;
  /// Candidate terms (PolyFitOptions::terms spelling); empty: rate, hysteresis, lag and
  /// gradient:<Tj> for every other temperature channel the runs share.
  std::vector<std::string> candidate_terms;
  int folds = 8;
  double min_gain = 0.10;
  LinearFitOptions linear;
  ProfileOptions profile;
  bool IsValid(std::string* error) const;
};

/// auto's test of one score against another: b beats a when its mean square is lower by at
/// least min_gain overall and lower in at least three quarters of the folds.
bool Beats(const CvScore& b, const CvScore& a, double min_gain);

/// auto's order rule (steps 1 and 3): of the scores of orders 1..5 (by_order[k] is order k + 1;
/// an order that could not be fitted has an infinite rms), the smallest order that no higher
/// order beats; 0 when none could be fitted.
int SmallestUnbeatenOrder(const std::vector<CvScore>& by_order, double min_gain);

/// The stopping rule in words, as the coefficient file's selection record states it.
std::string AutoRule(const AutoOptions& options);

/// auto on `runs`: the selected model fitted on every sample (preset "auto"), its selection
/// record attached. InputError for invalid options or data; NumericalError when not even
/// order 1 can be fitted.
PolyModel FitAuto(const std::vector<const sim::Run*>& runs, const AutoOptions& options);

/// The options that refit the selected model (its channel, order, offset, reference rule and
/// terms by kind): what `fit --model poly` would be told to reproduce it.
PolyFitOptions OptionsOf(const PolyModel& model, const AutoOptions& options);

}  // namespace rlg::model
