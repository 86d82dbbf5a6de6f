#pragma once
/// Stages 4 and 5 of the diagnosis: scoring a candidate against the baseline (docs/diagnosis.md
/// and 3). Pure functions of residuals; no simulation, no state.
///
/// A candidate is scored twice:
///  - in sample, by an information criterion on residuals whose lag-1 autocorrelation rho
///    shrinks the sample to n_eff = n (1 - rho) / (1 + rho) independent values:
///        gain = (SSR_base - SSR_ext) / s² · n_eff / n  -  k ln(max(n_eff, 2)),
///    with s² = SSR_base / n the baseline's residual variance and k the parameters the
///    candidate adds (the BIC penalty on n_eff);
///  - on data not used for its fit, by the held-out log-likelihood ratio of Gaussian residuals
///    with their variance profiled, heldout_gain = n ln(SSR_base / SSR_ext) (LogLikelihoodRatio;
///    information units, 2 ln L; > 0: the extension predicts unseen data better), and, for the
///    report, the held-out RMS ratio sqrt(SSR_base / SSR_ext) of the residuals' score-block means.
/// The bias search scores in sample by LogLikelihoodRatio too, less k ln n, on residuals
/// prewhitened by the candidate's noise model (network/bias_search.h).
/// Each kind's acceptance score (bias, thermal) is set by a parametric bootstrap (NullThreshold).

#include <vector>

namespace rlg::diagnosis {

/// Residuals of one model summarised for scoring: sum of squares, count, and the lag-1
/// autocorrelation within each series pooled over series, clamped to [0, 0.9] (a negative
/// value would inflate n_eff beyond n; above 0.9 n_eff is under a twentieth of n and the
/// estimate itself is unreliable).
struct ResidualFit {
  double ssr = 0.0;  ///< sum of squares (unit² of the residual)
  int n = 0;         ///< residuals
  double rho = 0.0;  ///< lag-1 autocorrelation in [0, 0.9]
  double rms() const;
};

/// ResidualFit of `series` (e.g. one per run): products across series boundaries are not
/// counted in rho.
ResidualFit Summarise(const std::vector<std::vector<double>>& series);

/// The information-criterion gain above (information units; > 0 favours the extension).
/// `base` needs n > 0 and ssr > 0.
double InformationGain(const ResidualFit& base, const ResidualFit& ext, int added_parameters);

/// sqrt(ssr_base / ssr_ext): above 1 the extension predicts unseen data better; 1 when
/// ssr_ext is zero (nothing to compare).
double HeldOutRmsRatio(double ssr_base, double ssr_ext);

/// n ln(ssr_base / ssr_ext) over the n residuals of `base` (information units, 2 ln L): the
/// log-likelihood ratio of the extension for Gaussian residuals whose variance each model fits. 0 when either has no residual or base.ssr is
/// 0; an ext.ssr of 0 counts as 1e-300 of base.ssr (a finite, very large gain).
double LogLikelihoodRatio(const ResidualFit& base, const ResidualFit& ext);

/// Ljung-Box portmanteau test of whiteness: p-value of Q = n (n + 2) sum_k rho_k² / (n - k),
/// k = 1..lags, against chi²(lags). 1 for a series too short (n <= lags + 1) or constant.
double LjungBoxP(const std::vector<double>& x, int lags);

/// The acceptance score of a kind of candidates from a null bootstrap's replicate scores (the
/// best candidate's score on each replicate; for bias, -infinity where none passed the
/// held-out test): max(min_score, largest replicate). With R replicates a null dataset beats
/// it with probability about 1 / (R + 1).
double NullThreshold(const std::vector<double>& replicate_scores, double min_score);

}  // namespace rlg::diagnosis
