#include "diagnosis/without_network/problem.h"

#include <algorithm>
#include <fmt/format.h>
#include <fmt/ranges.h>
#include <numeric>

#include "diagnosis/report.h"
#include "model/pairs.h"
#include "sim/errors.h"

namespace rlg::diagnosis {

namespace {

/// The channels of the first run that every run has; InputError when there are none.
std::vector<std::string> SharedChannels(const sim::Trace& data) {
  std::vector<std::string> out;
  for (const auto& ch : model::TemperatureChannels(data.runs.front())) {
    bool everywhere = true;
    for (const auto& run : data.runs) everywhere = everywhere && run.Has(ch);
    if (everywhere) out.push_back(ch);
  }
  if (out.empty()) {
    throw InputError(fmt::format("diagnose: {} has no temperature channel (T1, T2, .., T_name) that every run has "
                                 "(columns: {}): without a gyro file the bias is searched against measured "
                                 "temperatures",
                                 data.runs.front().Where(), fmt::join(data.runs.front().names, ",")));
  }
  return out;
}

/// Every run as one unit, laid out in blocks; InputError for a run without bias or too short.
std::vector<MeasuredUnit> WholeRuns(const sim::Trace& data, const DiagnoseOptions& o) {
  std::vector<MeasuredUnit> units;
  for (const auto& run : data.runs) {
    if (!run.Has("bias_dph")) {
      throw InputError(fmt::format("diagnose: {} has no bias_dph column: without a gyro file (--gyro) diagnose searches "
                                   "the bias alone against the measured temperatures; thermal-only data need a gyro "
                                   "file with a thermal network",
                                   run.Where()));
    }
    if (run.size() < 20) throw InputError(fmt::format("{}: {} samples are too few to diagnose", run.Where(), run.size()));
    MeasuredUnit u;
    u.run = static_cast<int>(units.size());
    u.prepared.run = &run;
    u.prepared.label = run.id;
    u.prepared.nuisance = u.run;
    BlockLayout(u.prepared, o);
    units.push_back(std::move(u));
  }
  return units;
}

/// The held-out split of network/problem.h: fit_runs, else all runs; a single one cut in time.
void Split(const sim::Trace& data, const DiagnoseOptions& o, MeasuredProblem& p) {
  for (const auto& id : o.fit_runs) data.FindRun(id);
  for (size_t u = 0; u < p.units.size(); ++u) {
    const std::string& id = p.units[u].prepared.run->id;
    const bool fit = o.fit_runs.empty() || std::find(o.fit_runs.begin(), o.fit_runs.end(), id) != o.fit_runs.end();
    (fit ? p.fit : p.held).push_back(static_cast<int>(u));
  }
  if (p.fit.empty()) throw InputError("diagnose: no runs to fit on");
  if (!p.held.empty() || p.fit.size() != 1) return;
  const MeasuredUnit whole = p.units[static_cast<size_t>(p.fit.front())];
  SplitRun split = SplitInTime(whole.prepared, o.single_run_pieces);
  p.split_note = std::move(split.note);
  p.units = {whole, whole};
  p.units[0].prepared = std::move(split.fit);
  p.units[1].prepared = std::move(split.held);
  p.fit = {0};
  p.held = {1};
}

/// Run r's blocks, their times and the block means of its channels, their rates and its bias.
void LayOutRun(MeasuredProblem& p, const PreparedRun& layout) {
  const sim::Run& run = *layout.run;
  const auto blocks = Blocks(run.t_s, layout.fit_block_s, layout.sample_period_s);
  std::vector<double> mids;
  for (const auto& b : blocks) mids.push_back(BlockMean(run.t_s, b));
  const auto n = static_cast<Eigen::Index>(blocks.size());
  Eigen::MatrixXd T(static_cast<Eigen::Index>(p.channels.size()), n), Tdot(T.rows(), n);
  for (Eigen::Index c = 0; c < T.rows(); ++c) {
    const auto& v = run.Column(p.channels[static_cast<size_t>(c)]);
    std::vector<double> means;
    for (const auto& b : blocks) means.push_back(BlockMean(v, b));
    const std::vector<double> per_min = RatePerMinute(mids, means);
    for (Eigen::Index k = 0; k < n; ++k) {
      T(c, k) = means[static_cast<size_t>(k)];
      Tdot(c, k) = per_min[static_cast<size_t>(k)] / 60.0;
    }
  }
  Eigen::VectorXd bias(n);
  const auto& b = run.Column("bias_dph");
  for (Eigen::Index k = 0; k < n; ++k) bias[k] = BlockMean(b, blocks[static_cast<size_t>(k)]);
  p.blocks.push_back(blocks);
  p.block_times.push_back(std::move(mids));
  p.T.push_back(std::move(T));
  p.Tdot.push_back(std::move(Tdot));
  p.bias.push_back(std::move(bias));
}

/// Scores and held-out RMS are on score blocks: the scored units must hold one.
void RequireScoreBlocks(const MeasuredProblem& p) {
  size_t blocks = 0;
  std::vector<std::string> labels;
  for (int u : p.Scored()) {
    const MeasuredUnit& unit = p.units[static_cast<size_t>(u)];
    blocks += unit.blocks.size() / static_cast<size_t>(unit.prepared.fit_blocks_per_score);
    labels.push_back(unit.prepared.label);
  }
  if (blocks > 0) return;
  const PreparedRun& run = p.units[static_cast<size_t>(p.Scored().front())].prepared;
  const std::string& file = run.run->source;
  throw InputError(fmt::format("diagnose: {}the scored data ({}) hold no {:g} s score block of {:g} s fit blocks in a "
                               "row; give longer or more runs",
                               file.empty() ? "" : file + ": ", fmt::join(labels, "; "), run.score_block_s(),
                               run.fit_block_s));
}

}  // namespace

std::vector<int> MeasuredProblem::Scored() const { return held.empty() ? fit : held; }

MeasuredProblem MakeMeasuredProblem(const sim::Trace& data, const DiagnoseOptions& o) {
  if (data.runs.empty()) throw InputError("diagnose: the data hold no run");
  if (o.per_run_source_gains) {
    throw InputError("diagnose: per-run source gains are gains of a thermal network's heat sources; without a gyro "
                     "file there is none");
  }
  if (o.power) {
    throw InputError("diagnose: the power is the thermal search's, against a calibrated network; without a gyro file "
                     "there is none");
  }
  MeasuredProblem p;
  p.options = o;
  p.channels = SharedChannels(data);
  const auto t1 = std::find(p.channels.begin(), p.channels.end(), "T1");
  p.channel_index = t1 == p.channels.end() ? 0 : static_cast<int>(t1 - p.channels.begin());
  p.channel = p.channels[static_cast<size_t>(p.channel_index)];
  p.units = WholeRuns(data, o);
  for (const auto& u : p.units) {
    p.runs.push_back(u.prepared.run);
    LayOutRun(p, u.prepared);
  }
  Split(data, o, p);
  for (auto& u : p.units) {
    const auto& blocks = p.blocks[static_cast<size_t>(u.run)];
    for (size_t i = 0; i < blocks.size(); ++i)
      if (u.prepared.Counts(u.prepared.run->t_s[blocks[i].first])) u.blocks.push_back(i);
  }
  RequireScoreBlocks(p);
  return p;
}

RunColumns BlockMeansOf(const MeasuredProblem& p, const std::function<std::vector<double>(int run)>& samples) {
  RunColumns out;
  for (size_t r = 0; r < p.runs.size(); ++r) {
    const std::vector<double> v = samples(static_cast<int>(r));
    Eigen::VectorXd m(static_cast<Eigen::Index>(p.blocks[r].size()));
    for (size_t k = 0; k < p.blocks[r].size(); ++k) m[static_cast<Eigen::Index>(k)] = BlockMean(v, p.blocks[r][k]);
    out.push_back(std::move(m));
  }
  return out;
}

BiasDesign MeasuredDesign(const MeasuredProblem& p, const std::vector<const RunColumns*>& columns, const RunColumns& y) {
  BiasDesign d;
  const auto cols = static_cast<Eigen::Index>(columns.size());
  for (const auto& u : p.units) {
    const auto rows = static_cast<Eigen::Index>(u.blocks.size());
    Eigen::MatrixXd X(rows, cols);
    Eigen::VectorXd v(rows);
    for (Eigen::Index i = 0; i < rows; ++i) {
      const auto k = static_cast<Eigen::Index>(u.blocks[static_cast<size_t>(i)]);
      for (Eigen::Index c = 0; c < cols; ++c) X(i, c) = (*columns[static_cast<size_t>(c)])[static_cast<size_t>(u.run)][k];
      v[i] = y[static_cast<size_t>(u.run)][k];
    }
    d.X.push_back(std::move(X));
    d.y.push_back(std::move(v));
  }
  d.prior_mean = Eigen::VectorXd::Zero(cols);
  d.prior_weight = Eigen::VectorXd::Zero(cols);
  return d;
}

std::vector<double> UnitScoreBlocks(const MeasuredProblem& p, const Eigen::VectorXd& e, int u) {
  const int per = p.units[static_cast<size_t>(u)].prepared.fit_blocks_per_score;
  std::vector<double> out;
  for (Eigen::Index i = 0; i + per <= e.size(); i += per) out.push_back(e.segment(i, per).mean());
  return out;
}

MeasuredFit FitMeasured(const MeasuredProblem& p, const BiasDesign& d) {
  MeasuredFit out;
  const Eigen::VectorXd beta = FitBias(d, p.fit);
  std::vector<std::vector<double>> in, held;
  for (int u : p.fit) {
    const Eigen::VectorXd e = BiasResidual(d, beta, u);
    in.emplace_back(e.data(), e.data() + e.size());
  }
  out.in_sample = Summarise(in);
  out.held_residuals = HeldOutBias(d, p.fit, p.held);
  for (int u : p.Scored()) held.push_back(UnitScoreBlocks(p, out.held_residuals[static_cast<size_t>(u)], u));
  out.held_out = Summarise(held);
  return out;
}

double InSampleSsr(const MeasuredProblem& p, const BiasDesign& d) {
  const Eigen::VectorXd beta = FitBias(d, p.fit);
  double ssr = 0.0;
  for (int u : p.fit) ssr += BiasResidual(d, beta, u).squaredNorm();
  return ssr;
}

}  // namespace rlg::diagnosis
