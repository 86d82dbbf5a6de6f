#pragma once
/// Stage 5 of a diagnosis: the bias search. Every bias effect of the catalog on every target is
/// a candidate: its term at unit coefficient (the function the simulator's BiasModel calls)
/// joins the linear bias fit (network/bias_design.h, statistics/bias_fit.h) as an extra regressor on the searched
/// model's node temperatures, beside the baseline physics and the terms accepted so far.
///
/// Every fit is feasible generalised least squares (PrewhitenByCandidate in the source): a gyro's bias
/// instability drifts for an hour, and ordinary least squares on 10 s blocks would count each
/// block as independent evidence. A candidate is fitted by ordinary least squares; the
/// autoregressive model of its residuals (one order for the whole search, the baseline's by AIC)
/// prewhitens (statistics/bias_fit.h Prewhiten) its design and the baseline's, and both are
/// fitted again. Its score is the log-likelihood ratio of the prewhitened in-sample residuals
/// less k ln n (statistics/score.h: LogLikelihoodRatio; k = its columns plus the shape
/// parameters searched on the data); its held-out gain the same ratio on the prewhitened
/// held-out residuals: the held-out runs, or the better of leave-one-run-out and two folds in
/// time (statistics/bias_fit.h CrossValidatedInTime); its held-out RMS ratio, for the report,
/// that of the residuals' score-block means as measured (HeldOutBias).
/// An effect that searches a shape (a mode hop's temperatures) is handed the gain of a candidate
/// column against the baseline's ordinary least-squares residual (ColumnGain,
/// catalog/effect_search.h). One candidate per (cause, canonical target): the best-scoring of
/// its columns.
///
/// Its threshold comes from the bias null bootstrap (network/bias_null.h).

#include <Eigen/Core>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "diagnosis/network/bias_design.h"
#include "diagnosis/network/calibrate.h"
#include "diagnosis/candidate.h"
#include "diagnosis/diagnose.h"
#include "diagnosis/network/model.h"
#include "diagnosis/network/prediction.h"
#include "diagnosis/network/problem.h"
#include "diagnosis/statistics/off_span.h"

namespace rlg::diagnosis {

/// What the bias null bootstrap's replicates share of a shape search (ColumnGain::Keyed): per
/// key, its column projected off the baseline's centred regressors (statistics/off_span.h). A
/// replicate's tracks and regressors are the data's, only its bias differs, so the projection
/// of a grid point is the same in every replicate; the gain of each is then a product with the
/// replicate's residual, the same bytes as projecting it again. Up to kMaxDoubles doubles are
/// kept (64 MB).
struct ShapeProjections {
  static constexpr size_t kMaxDoubles = size_t{1} << 23;
  std::map<std::vector<double>, OffSpan> by_key;
  size_t doubles = 0;
  Eigen::Index rows = -1, rank = -1;  ///< of the projection they were made with (checked)
};

struct BiasSearch {
  std::vector<Candidate> candidates;       ///< in catalog order
  std::vector<std::vector<Extra>> extras;  ///< per candidate, its columns
  std::vector<int> counted;                ///< per candidate, the parameters its score counts (k)
};

/// Every bias effect on every target not in `taken` (cause and canonical target) as a candidate
/// of model m (pred: its prediction on every run), beside the `accepted` columns, scored on the
/// data's bias or, given `bias_data` (per run, one value per counted fit block), on those
/// instead (a null replicate). A replicate's candidates carry what its threshold needs: their
/// scores, and held-out gains from the best score down to the first above min_heldout_gain (NaN
/// below it); no held-out RMS ratio or shape note. Replicates of one bootstrap pass the same
/// `shared` (nullptr: nothing shared).
BiasSearch SearchBias(const Problem& p, const Model& m, const std::vector<Prediction>& pred,
                      const std::vector<Extra>& accepted, const std::set<CauseTarget>& taken,
                      const std::vector<Eigen::VectorXd>* bias_data = nullptr,
                      ShapeProjections* shared = nullptr);

/// Bias candidates beside `accepted` on model m, scored as SearchBias scores them but two at a
/// time under one noise model: the AR model (the search's order) of the residuals of the fit
/// with both, which hold neither term. SearchBias prewhitens each candidate by its own
/// residuals' model, and a column that takes up some of the slow noise whitens its residuals
/// further and scores higher for it: on a near twin (cosine 0.98) the difference of two such
/// scores spread 2.6x as much as under one model, so the tie rule (statistics/rank.h) compares
/// bias candidates with this. Keeps references to p, m and pred: they must outlive it.
class PairedScores {
 public:
  /// The leader: its columns and the parameters its score counts (k).
  PairedScores(const Problem& p, const Model& m, const std::vector<Prediction>& pred, const std::vector<Extra>& accepted,
               const std::vector<Extra>& leader, int k_leader);
  /// The score of the candidate of columns `rival` (k_rival parameters) less the leader's.
  double Difference(const std::vector<Extra>& rival, int k_rival) const;

 private:
  std::vector<Extra> Beside(std::vector<Extra> extra) const;
  const Problem& p_;
  const Model& m_;
  const std::vector<Prediction>& pred_;
  std::vector<Extra> accepted_, leader_;
  int k_leader_;
  int order_;
  BiasDesign d_leader_;
};

/// The linearised power of the bias search on model m (pred: its prediction on every run)
/// against the acceptance score `threshold` (Diagnosis::power, statistics/power.h): every
/// candidate SearchBias would score, its column at the catalog's typical size (a searched shape:
/// the shape the search finds on these data, the form of most noncentrality kept), prewhitened
/// by the AR model of the baseline's residuals (the search's order), less what the baseline's
/// columns take up (FitBias's offsets too); its noncentrality, the sizes detected and named with
/// probability kPowerLevel and the candidate of nearest column. Sizes are of the parameter the
/// column's coefficient moves (a mode hop's step beyond the path-length control's reset).
/// Linear algebra on the prediction: no simulation.
std::vector<EffectPower> BiasPower(const Problem& p, const Model& m, const std::vector<Prediction>& pred,
                                   double threshold);

/// The search on a calibration (empty without bias data): its candidates.
std::vector<Candidate> FirstBiasCandidates(const Problem& p, const Calibration& cal);

}  // namespace rlg::diagnosis
