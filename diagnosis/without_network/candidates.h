#pragma once
/// Stage 5's candidates in a diagnosis without a thermal network: what may explain the bias
/// beyond the baseline polynomial, each a column of the bias regression or a family of columns
/// along one profiled parameter.
///
///  - The catalog's bias effects whose term reads temperature tracks alone
///    (sim::Effect::ComputedFromTracks): bias.temperature_rate on each channel, bias.gradient
///    between each pair of channels, bias.hysteresis on each channel (only k_heating - k_cooling
///    is identifiable beside the polynomial's linear term; sim/effects/hysteresis.h). Their
///    regressors are the effects' own (Effect::Regressors at unit coefficient), on the channels'
///    block means and rates as node tracks: each channel a node that its own sensor reads.
///  - poly.lag on the bias-temperature channel T, the model family's lag term
///    (model/poly_model.h): T_L - T (°C), T_L the first-order lag of T of time constant tau
///    (FirstOrderLag, per sample from each run's first), coefficient k_dph_per_C (°/h/°C); tau
///    (tau_s) profiled over [2 dt, half the longest run] (dt the median sample period), as
///    FitPoly bounds it.
///  - poly.hysteresis on T, the model family's hysteresis term: T - play_w(T) (PlayOperator),
///    +w/2 heating and -w/2 cooling, a loop w wide; coefficient k_dph_per_C (°/h/°C, the loop is
///    k w tall: reported as its amplitude_dph, k w / 2, the bias's +- between the branches); the
///    width w (width_C) profiled over [span / 200, span / 2], span the fit part's range of T (as
///    FitPoly bounds it).
///  - poly.order on T, the baseline polynomial's next power d^(order+1) (d = clamp(T, T_min,
///    T_max) - T_ref as the baseline's; none at order 5), coefficient c<n>_dph_per_C<n>: the
///    order the blocked cross-validation chose is checked again by the held-out test, beside the
///    other causes (identical chamber cycles put the same phase into every fold, and a FOG-like
///    log cut into its three cycles got a line for a quadratic).
///
/// The lag and the loop are computed per sample, then averaged over each fit block like the
/// bias; nothing here fits.

#include <functional>
#include <string>
#include <vector>

#include "diagnosis/without_network/problem.h"
#include "model/poly_model.h"
#include "sim/effect.h"

namespace rlg::diagnosis {

struct MeasuredCandidate {
  std::string cause;   ///< "bias.temperature_rate", .., "poly.lag", "poly.hysteresis", "poly.order"
  std::string target;  ///< a channel "T1", or a pair of channels "T1-T2"
  int searched = 0;    ///< profiled parameters: 0 (one fixed column) or 1
  double lo = 0.0, hi = 0.0;  ///< the profiled parameter's bounds (0 < lo < hi)
  /// The column at the profiled parameter x (x unused when searched is 0).
  std::function<RunColumns(double x)> column;
  /// The reported parameters for a fitted coefficient of the column, at x.
  std::function<sim::ParameterMap(double coefficient, double x)> parameters;
};

/// Every candidate above for the problem, the baseline's range and reference in `baseline`:
/// the catalog's first (in registry order, then its targets' order), then poly.lag,
/// poly.hysteresis and poly.order.
std::vector<MeasuredCandidate> MeasuredCandidates(const MeasuredProblem& p, const model::PolySpec& baseline);

}  // namespace rlg::diagnosis
