#include "diagnosis/without_network/baseline.h"

#include <cmath>
#include <deque>
#include <fmt/format.h>
#include <fmt/ranges.h>
#include <limits>

#include "model/model_selection.h"
#include "model/poly_fit.h"
#include "sim/errors.h"

namespace rlg::diagnosis {

namespace {

/// The fit part as runs: the fitted runs themselves, or a single run's fitted pieces, each
/// its own run of the channel and the bias (a polynomial has no history, so a piece fits and
/// scores as it would inside its run).
std::vector<const sim::Run*> FitPart(const MeasuredProblem& p, std::deque<sim::Run>& pieces) {
  std::vector<const sim::Run*> out;
  for (int u : p.fit) {
    const PreparedRun& prepared = p.units[static_cast<size_t>(u)].prepared;
    const sim::Run& run = *prepared.run;
    if (prepared.windows.empty()) {
      out.push_back(&run);
      continue;
    }
    const auto& T = run.Column(p.channel);
    const auto& b = run.Column("bias_dph");
    for (const auto& [from, to] : prepared.windows) {
      sim::Run& piece = pieces.emplace_back();
      piece.id = fmt::format("{} (t = {:.0f}-{:.0f} s)", run.id, from, std::min(to, run.t_s.back()));
      auto& pT = piece.AddColumn(p.channel);
      auto& pb = piece.AddColumn("bias_dph");
      for (size_t k = 0; k < run.size(); ++k) {
        if (run.t_s[k] < from || run.t_s[k] >= to) continue;
        piece.t_s.push_back(run.t_s[k]);
        pT.push_back(T[k]);
        pb.push_back(b[k]);
      }
      out.push_back(&piece);
    }
  }
  return out;
}

/// The polynomial's columns d^k (k = 1..order) of every run, block means.
std::vector<RunColumns> Columns(const MeasuredProblem& p, const model::PolySpec& spec) {
  std::vector<std::vector<std::vector<double>>> powers(static_cast<size_t>(spec.order));  // [k][run][sample]
  for (const sim::Run* run : p.runs) {
    model::PolyRegressors g(spec);
    const auto& T = run->Column(p.channel);
    Eigen::VectorXd row(static_cast<Eigen::Index>(g.names().size()));
    for (auto& v : powers) v.emplace_back(run->size());
    for (size_t i = 0; i < run->size(); ++i) {
      g.Next(run->t_s[i], &T[i], row.data());
      for (int k = 1; k <= spec.order; ++k) powers[static_cast<size_t>(k - 1)].back()[i] = row[k];  // row[0]: c0's 1
    }
  }
  std::vector<RunColumns> out;
  for (const auto& v : powers) out.push_back(BlockMeansOf(p, [&v](int r) { return v[static_cast<size_t>(r)]; }));
  return out;
}

}  // namespace

PolynomialBaseline ChooseBaseline(const MeasuredProblem& p) {
  std::deque<sim::Run> pieces;
  const std::vector<const sim::Run*> runs = FitPart(p, pieces);
  const model::AutoOptions rule;  // the model family's folds and margin
  const std::vector<model::RowMask> folds = model::BlockFolds(runs, rule.folds);
  model::PolyFitOptions o;
  o.channel = p.channel;
  o.offset = model::OffsetRule::kFitted;
  PolynomialBaseline out;
  std::vector<model::CvScore> scores;
  std::string why;
  for (int order = 1; order <= 5; ++order) {
    o.order = order;
    try {
      scores.push_back(model::PolyCv(runs, folds, o));
    } catch (const NumericalError& e) {  // a fold that cannot identify this order
      why = e.what();
      model::CvScore failed;
      failed.rms = std::numeric_limits<double>::infinity();
      failed.fold_ms.assign(folds.size(), failed.rms);
      scores.push_back(failed);
    }
    out.cv_rms.push_back(scores.back().rms);
  }
  const int order = model::SmallestUnbeatenOrder(scores, rule.min_gain);
  if (order == 0) throw NumericalError(fmt::format("diagnose: no polynomial in {} could be fitted: {}", p.channel, why));
  o.order = order;
  out.spec = model::FitPoly(runs, o).spec;
  out.columns = Columns(p, out.spec);
  return out;
}

std::string BaselineNote(const PolynomialBaseline& b) {
  std::vector<std::string> cv;
  for (double v : b.cv_rms) cv.push_back(std::isfinite(v) ? fmt::format("{:.4g}", v) : std::string("-"));
  return fmt::format("baseline: the polynomial of order {} in {} (T_ref {:.4g} °C, range {:.4g} ... {:.4g} °C of the fit "
                     "part), chosen by blocked cross-validation on the fit part (RMS of orders 1-5: {} °/h; the smallest "
                     "order no higher order beats by 10 % overall and in three quarters of 8 folds)",
                     b.spec.order, b.spec.channel, b.spec.reference_C, b.spec.range_C[0], b.spec.range_C[1],
                     fmt::join(cv, ", "));
}

}  // namespace rlg::diagnosis
