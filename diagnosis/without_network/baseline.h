#pragma once
/// Stage 2 of a diagnosis without a thermal network: its baseline, the best polynomial in the
/// bias-temperature channel T (model/poly_model.h, fitted offset),
///
///     B = c0 + sum_{k=1..order} c_k d^k,   d = clamp(T, T_min, T_max) - T_ref      (°/h, °C)
///
/// chosen on the fit part alone by the model family's blocked cross-validation
/// (model/model_selection.h): every fitted run, or each fitted piece of a single run, is cut into
/// 8 contiguous pieces; fold k holds out piece k of each and fits on the rest (FitPoly); orders
/// 1..5 are scored by the RMS of the compensated bias on the held-out pieces, and the order is
/// the smallest that no higher order beats (SmallestUnbeatenOrder: a mean square 10 % lower
/// overall and lower in three quarters of the folds). [T_min, T_max] and T_ref = their middle
/// are the fit part's (FitPoly at the chosen order). A fitted piece too short for 8 folds of 2
/// samples is refused by BlockFolds (InputError).
///
/// The regression of the later stages takes the polynomial's columns d^k (PolyRegressors, the
/// compensator's own regressors, averaged over each fit block); its constant is each unit's
/// offset (statistics/bias_fit.h), so c0 is not among them.

#include <string>
#include <vector>

#include "diagnosis/without_network/problem.h"
#include "model/poly_model.h"

namespace rlg::diagnosis {

struct PolynomialBaseline {
  model::PolySpec spec;         ///< channel, order, range and reference of the fit part
  std::vector<double> cv_rms;   ///< per order 1..5: its cross-validated RMS (°/h); infinite where a fold could not fit it
  std::vector<RunColumns> columns;  ///< d, d², .., d^order, block means
};

/// The baseline of `p` (above). NumericalError when no order can be fitted (a channel that does
/// not move over the fit part).
PolynomialBaseline ChooseBaseline(const MeasuredProblem& p);

/// "order 2 in T1 (T_ref 28.2 °C, range -11.4 ... 74.0 °C); cross-validated RMS of orders 1-5 on
/// the fit part: 30.0, 21.9, 23.0, 24.1, 25.9 °/h".
std::string BaselineNote(const PolynomialBaseline& b);

}  // namespace rlg::diagnosis
