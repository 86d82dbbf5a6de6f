#include "diagnosis/network/problem.h"

#include <algorithm>
#include <cmath>
#include <fmt/format.h>
#include <fmt/ranges.h>
#include <numeric>

#include "sim/errors.h"
#include "sim/noise.h"

namespace rlg::diagnosis {

namespace {

/// The runs named in o.fit_runs (all when it is empty) are fitted, the others held out; a
/// single fit run with none held out is cut in time (docs/diagnosis.md): it is cut into equal
/// pieces; the model is fitted on the even ones and predicts the odd ones, simulated on from
/// power-on.
void SplitFitAndHeld(const sim::Trace& data, const DiagnoseOptions& o, Problem& p) {
  for (size_t r = 0; r < p.runs.size(); ++r) {
    const bool fit = o.fit_runs.empty() ||
                     std::find(o.fit_runs.begin(), o.fit_runs.end(), p.runs[r].run->id) != o.fit_runs.end();
    (fit ? p.fit : p.held).push_back(static_cast<int>(r));
  }
  for (const auto& id : o.fit_runs) data.FindRun(id);
  if (p.fit.empty()) throw InputError("diagnose: no runs to fit on");
  if (p.held.empty() && p.fit.size() == 1) {
    SplitRun split = SplitInTime(p.runs[static_cast<size_t>(p.fit.front())], o.single_run_pieces);
    p.split_note = std::move(split.note);
    p.runs = {std::move(split.fit), std::move(split.held)};
    p.fit = {0};
    p.held = {1};
  }
}

/// Run r's counted fit blocks, their times, and its logged ambient's curve and noise.
void LayOutRun(Problem& p, size_t r) {
  const auto& t = p.runs[r].run->t_s;
  const auto blocks = Blocks(t, p.runs[r].fit_block_s, p.runs[r].sample_period_s);
  std::vector<double> mids;
  for (const auto& b : blocks) mids.push_back(BlockMean(t, b));
  p.fit_blocks.emplace_back();
  p.block_times.emplace_back();
  p.block_spans.emplace_back();
  for (size_t i = 0; i < blocks.size(); ++i) {
    if (!p.runs[r].Counts(t[blocks[i].first])) continue;
    p.fit_blocks.back().push_back(blocks[i]);
    p.block_times.back().push_back(mids[i]);
    p.block_spans.back().push_back(TimesOf(t, blocks[i]));
  }
  // A measured ambient enters as the piecewise-linear curve through its means over
  // ambient blocks of about 1 s (at least one sample): short enough that the curve cuts a
  // ramp's corner by a negligible area (r h² / 8: through 10 s means, 0.2 °C s at a
  // 1 °C/min corner, which the 5-minute cabinet turned into a 0.6 mK error, more than the
  // noise of 0.1 s data), long enough to average a fast-sampled log. Points on a straight
  // stretch (a ramp, a dwell) are then dropped where the curve moves by less than a tenth
  // of the score-block noise (a network passes an ambient error at most one to one, so
  // the temperatures move by less than that too) or by less than three times the points'
  // own noise, up to the score-block noise (the 4-decimal rounding of a CSV column alone is
  // 5e-5 °C; a tolerance below it kept every point of a ramp, and the breakpoints made
  // diagnose 5x slower), while CVODE (which restarts at every breakpoint) gets long steps.
  // Never beyond the score-block noise itself: where a record's nonzero second differences
  // are mostly its corners (60 s samples of an exact ramp), PointNoise measures them. A
  // noisy record is smoothed instead (LoggedAmbientCurve), and a step between two samples is
  // a step at the second (InputJumps).
  const int amb = p.runs[r].run->Find("T_amb");
  p.ambient_noise.push_back(0.0);
  p.start_sd.push_back(0.0);
  if (amb >= 0) {
    p.runs[r].ambient =
        LoggedAmbient(t, p.runs[r].run->columns[amb], p.runs[r].sample_period_s, p.noise, &p.start_sd.back());
    if (p.runs[r].ambient_known) {
      std::vector<std::pair<double, double>> pts;
      for (size_t k = 0; k < t.size(); ++k) pts.emplace_back(t[k], p.runs[r].run->columns[amb][k]);
      p.ambient_noise.back() = NoiseAtEveryPoint(pts);
    }
  }
}

/// Scores and held-out RMS are on score blocks (BlockLayout: whole fit blocks of a run in a
/// row): data whose scored runs hold none cannot be diagnosed.
void RequireScoreBlocks(const Problem& p) {
  size_t blocks = 0;
  std::vector<std::string> labels;
  for (int r : p.Scored()) {
    const auto i = static_cast<size_t>(r);
    blocks += p.fit_blocks[i].size() / static_cast<size_t>(p.runs[i].fit_blocks_per_score);
    labels.push_back(p.runs[i].label);
  }
  if (blocks == 0) {
    const PreparedRun& run = p.runs[static_cast<size_t>(p.Scored().front())];
    const std::string& file = p.runs.front().run->source;
    throw InputError(fmt::format("diagnose: {}the scored data ({}) hold no {:g} s score block of {:g} s fit blocks in a "
                                 "row; give longer or more runs",
                                 file.empty() ? "" : file + ": ", fmt::join(labels, "; "), run.score_block_s(),
                                 run.fit_block_s));
  }
}

}  // namespace

std::vector<int> Problem::All() const {
  std::vector<int> a(runs.size());
  std::iota(a.begin(), a.end(), 0);
  return a;
}

std::vector<int> Problem::Scored() const { return held.empty() ? fit : held; }

namespace {

/// Problem::measured for the problem's fit blocks as they stand.
void MeasureSensors(Problem& p) {
  p.measured.assign(p.runs.size(), std::vector<Eigen::VectorXd>(p.nominal.sensors.size()));
  for (size_t r = 0; r < p.runs.size(); ++r)
    for (size_t s = 0; s < p.nominal.sensors.size(); ++s)
      if (p.runs[r].sensor_col[s] >= 0)
        p.measured[r][s] = BlockMeans(p, p.runs[r].run->columns[p.runs[r].sensor_col[s]], static_cast<int>(r));
}

}  // namespace

Problem MakeProblem(const sim::Trace& data, const sim::GyroConfig& nominal, const DiagnoseOptions& o) {
  Problem p;
  p.nominal = nominal;
  p.options = o;
  p.per_run_source_gains = o.per_run_source_gains;
  p.runs = Prepare(data, nominal, o);
  p.knobs = BaselineKnobs(nominal);
  p.noise = ScoreBlockNoise(p.runs);
  p.solver = SolverForData(p.noise);
  p.n_nodes = static_cast<int>(nominal.network.nodes.size());
  p.has_bias = std::all_of(p.runs.begin(), p.runs.end(), [](const PreparedRun& run) { return run.bias_col >= 0; });
  p.has_logged_ambient = std::any_of(p.runs.begin(), p.runs.end(), [](const PreparedRun& run) { return run.ambient_known; });
  SplitFitAndHeld(data, o, p);
  for (size_t r = 0; r < p.runs.size(); ++r) LayOutRun(p, r);
  RequireScoreBlocks(p);
  const double white = 60.0 * nominal.noise.arw_deg_per_sqrt_h / std::sqrt(p.runs.front().fit_block_s);
  // A noise-free gyro file still needs a scale for its prior: 1e-6 °/h, far below any
  // gyro's noise, keeps the prior from deciding anything the data can.
  p.bias_block_noise = std::max(std::hypot(white, sim::kFlickerFloor * nominal.noise.bias_instability_dph), 1e-6);
  MeasureSensors(p);
  return p;
}

Problem InTimeFold(const Problem& p, int f) {
  Problem q = p;
  for (int r : p.fit) {
    // The windows a single run is held out in (SplitInTime): its fit windows are fold 0.
    const SplitRun split = SplitInTime(p.runs[r], 4);
    const PreparedRun& fold = f == 0 ? split.fit : split.held;
    q.fit_blocks[r].clear();
    q.block_times[r].clear();
    q.block_spans[r].clear();
    for (size_t i = 0; i < p.fit_blocks[r].size(); ++i) {
      if (!fold.Counts(p.block_times[r][i])) continue;
      q.fit_blocks[r].push_back(p.fit_blocks[r][i]);
      q.block_times[r].push_back(p.block_times[r][i]);
      q.block_spans[r].push_back(p.block_spans[r][i]);
    }
  }
  MeasureSensors(q);
  return q;
}

Model NominalModel(const Problem& p) {
  Model m;
  m.base.resize(p.knobs.size());
  for (size_t i = 0; i < p.knobs.size(); ++i) m.base[i] = p.knobs[i].nominal;
  m.ambient.resize(p.runs.size());
  m.start.assign(p.runs.size(), 0.0);
  if (p.per_run_source_gains)
    m.run_gain.assign(p.runs.size(), std::vector<double>(p.nominal.network.sources.size(), 1.0));
  for (size_t r = 0; r < p.runs.size(); ++r) {
    // Unknown ambient: start at the first reading of the sensors after a soak.
    double s = 0.0;
    int c = 0;
    for (int col : p.runs[r].sensor_col)
      if (col >= 0) s += p.runs[r].run->columns[col][0], ++c;
    m.ambient[r] = s / c;
  }
  return m;
}

Eigen::VectorXd BlockMeans(const Problem& p, const std::vector<double>& v, int r) {
  Eigen::VectorXd y(static_cast<Eigen::Index>(p.fit_blocks[r].size()));
  for (size_t i = 0; i < p.fit_blocks[r].size(); ++i) y[static_cast<Eigen::Index>(i)] = BlockMean(v, p.fit_blocks[r][i]);
  return y;
}

std::vector<double> ToScoreBlocks(const Problem& p, const Eigen::Ref<const Eigen::VectorXd>& e, int r) {
  const int per = p.runs[static_cast<size_t>(r)].fit_blocks_per_score;
  std::vector<double> out;
  for (Eigen::Index i = 0; i + per <= e.size(); i += per) out.push_back(e.segment(i, per).mean());
  return out;
}

}  // namespace rlg::diagnosis
