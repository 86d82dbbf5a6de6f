#include "model/diagnose.h"

#include <algorithm>
#include <ceres/ceres.h>
#include <ceres/normal_prior.h>
#include <cmath>
#include <fmt/format.h>
#include <fmt/ranges.h>
#include <functional>
#include <limits>
#include <numeric>
#include <set>

#include "model/allan.h"
#include "model/diagnosis_bias_fit.h"
#include "model/diagnosis_prepare.h"
#include "model/diagnosis_screen.h"
#include "model/diagnosis_rank.h"
#include "model/diagnosis_score.h"
#include "sim/effect_registry.h"
#include "sim/errors.h"
#include "sim/noise.h"
#include "sim/simulator.h"
#include "sim/stats.h"

namespace rlg::model {
namespace {

using diagnosis::Blocks;
using diagnosis::BlockMean;
using diagnosis::PreparedRun;
using sim::GyroConfig;
using sim::Profile;

// ---------------------------------------------------------------------------------------------
// Model: nominal gyro + baseline knobs + effects (+ per-run ambient when unknown)

struct BaseKnob {
  std::string name;
  double nominal;
  std::function<void(GyroConfig&, double)> set;
};

std::vector<BaseKnob> BaselineKnobs(const GyroConfig& g) {
  std::vector<BaseKnob> k;
  const auto& net = g.network;
  auto node_name = [&](int i) { return i == sim::kAmbient ? std::string("ambient") : net.nodes[i].name; };
  for (size_t i = 0; i < net.nodes.size(); ++i) {
    k.push_back({"C:" + net.nodes[i].name, net.nodes[i].heat_capacity_J_per_K,
                 [i](GyroConfig& c, double v) { c.network.nodes[i].heat_capacity_J_per_K = v; }});
  }
  for (size_t l = 0; l < net.links.size(); ++l) {
    if (net.links[l].conductance_W_per_K <= 0.0) continue;
    k.push_back({"G:" + node_name(net.links[l].a) + "-" + node_name(net.links[l].b), net.links[l].conductance_W_per_K,
                 [l](GyroConfig& c, double v) { c.network.links[l].conductance_W_per_K = v; }});
  }
  for (size_t r = 0; r < net.radiation.size(); ++r) {
    if (net.radiation[r].emissivity_area_m2 <= 0.0) continue;
    k.push_back({"eA:" + node_name(net.radiation[r].a) + "-" + node_name(net.radiation[r].b),
                 net.radiation[r].emissivity_area_m2,
                 [r](GyroConfig& c, double v) { c.network.radiation[r].emissivity_area_m2 = v; }});
  }
  for (size_t s = 0; s < net.sources.size(); ++s) {
    if (!net.sources[s].driven_by_data && net.sources[s].power_W <= 0.0) continue;
    // The file's gain (1 unless a calibrated file, e.g. an extended-gyro.toml, sets it).
    k.push_back({"gain:" + net.sources[s].name, net.sources[s].gain, [s](GyroConfig& c, double v) {
                   c.network.sources[s].gain = v;
                 }});
  }
  return k;
}

struct Model {
  std::vector<double> base;              ///< baseline knob values
  std::vector<sim::EffectSpec> effects;  ///< accepted (and candidate) effects with parameters
  std::vector<double> ambient;           ///< per run, used where the ambient is unknown
  std::vector<std::vector<double>> run_gain;  ///< per run and data-driven source (per_run_source_gains)
};

GyroConfig Build(const GyroConfig& nominal, const std::vector<BaseKnob>& knobs, const Model& m) {
  GyroConfig g = nominal;
  for (size_t i = 0; i < knobs.size(); ++i) knobs[i].set(g, m.base[i]);
  for (const auto& e : m.effects) sim::ApplyEffect(e, g);
  return g;
}

struct Prediction {
  std::vector<std::vector<double>> sensor;  ///< per gyro sensor, per fit block
  Eigen::MatrixXd T, Tdot;                  ///< nodes x fit blocks (original nodes only)
};

/// The sample times of one fit block: their mean and their variance about it.
struct BlockTimes {
  double mean, variance;
};

BlockTimes TimesOf(const std::vector<double>& t, std::pair<size_t, size_t> b) {
  BlockTimes out{0.0, 0.0};
  for (size_t i = b.first; i < b.second; ++i) out.mean += t[i];
  out.mean /= static_cast<double>(b.second - b.first);
  for (size_t i = b.first; i < b.second; ++i) out.variance += (t[i] - out.mean) * (t[i] - out.mean);
  out.variance /= static_cast<double>(b.second - b.first);
  return out;
}

/// Block means of smooth quantities (rows of q, one column per block) from their values at
/// the blocks' mean sample times: the mean over a block's samples is q(m) + q''(m) var(t) / 2
/// to fourth order, with q'' / 2 the second divided difference through this block's and its
/// neighbours' values (the nearest three at a run's ends). Taking q(m) alone was wrong by
/// q'' var / 2 where an ambient corner starts a curvature: 0.22 mK on the cabinet after a
/// ramp's start (10 s blocks of 0.1 s or 1 s data), 1.7 times the noise of a 100 s mean of
/// 0.1 s data. One-sample blocks have no variance and stay as they are.
void ToBlockMeans(const std::vector<BlockTimes>& blocks, Eigen::Ref<Eigen::MatrixXd> q) {
  const auto n = static_cast<Eigen::Index>(blocks.size());
  if (n < 3) return;
  const Eigen::MatrixXd at_mean = q;
  for (Eigen::Index k = 0; k < n; ++k) {
    const double var = blocks[static_cast<size_t>(k)].variance;
    if (var <= 0.0) continue;
    const Eigen::Index c = std::clamp<Eigen::Index>(k, 1, n - 2);
    const double t0 = blocks[static_cast<size_t>(c - 1)].mean, t1 = blocks[static_cast<size_t>(c)].mean,
                 t2 = blocks[static_cast<size_t>(c + 1)].mean;
    q.col(k) += var * (((at_mean.col(c + 1) - at_mean.col(c)) / (t2 - t1) - (at_mean.col(c) - at_mean.col(c - 1)) / (t1 - t0)) /
                       (t2 - t0));
  }
}

/// Noise-free simulation of the block means of a run's fit blocks (ToBlockMeans of each
/// output at the blocks' mean sample times).
Prediction Simulate(const GyroConfig& g, const PreparedRun& p, const std::vector<BlockTimes>& blocks, double ambient_C,
                    int n_nodes, const sim::SolverOptions& solver) {
  std::vector<int> sensor_state;
  const sim::ThermalNetwork net = sim::BuildNetwork(g, &sensor_state);
  std::vector<Profile> power;
  for (size_t s = 0; s < g.network.sources.size(); ++s) {
    const auto& src = g.network.sources[s];
    power.push_back(p.power_logged[s] ? p.data_power[s] : Profile::Constant(src.power_W));
  }
  const Profile ambient = p.ambient_known ? p.ambient : Profile::Constant(ambient_C);
  const sim::ThermalSystem system(net, ambient, power);
  const auto n_sensors = static_cast<Eigen::Index>(g.sensors.size());
  // Powered on after a soak: every state starts at the ambient of the first sample, which is
  // integrated from there through each block's mean sample time.
  std::vector<double> t = {p.run->t_s.front()};
  for (const auto& b : blocks) t.push_back(b.mean);
  const Eigen::VectorXd x0 = Eigen::VectorXd::Constant(net.num_states(), ambient.Value(p.run->t_s.front()));
  // Rows: sensors, node temperatures, node rates; one column per block.
  Eigen::MatrixXd q(n_sensors + 2 * n_nodes, static_cast<Eigen::Index>(blocks.size()));
  sim::IntegrateThermal(system, t, x0, solver, [&](size_t j, double, const Eigen::VectorXd& x, const Eigen::VectorXd& xdot) {
    if (j == 0) return;
    const auto c = static_cast<Eigen::Index>(j - 1);
    for (Eigen::Index i = 0; i < n_sensors; ++i)
      q(i, c) = x[sensor_state[static_cast<size_t>(i)]] + g.sensors[static_cast<size_t>(i)].offset_C;
    q.block(n_sensors, c, n_nodes, 1) = x.head(n_nodes);
    q.block(n_sensors + n_nodes, c, n_nodes, 1) = xdot.head(n_nodes);
  });
  ToBlockMeans(blocks, q);
  Prediction out;
  out.sensor.resize(g.sensors.size());
  for (Eigen::Index i = 0; i < n_sensors; ++i) {
    const Eigen::VectorXd row = q.row(i).transpose();
    out.sensor[static_cast<size_t>(i)].assign(row.data(), row.data() + row.size());
  }
  out.T = q.middleRows(n_sensors, n_nodes);
  out.Tdot = q.bottomRows(n_nodes);
  return out;
}

// ---------------------------------------------------------------------------------------------
// The diagnosis engine

/// A free parameter of an optimisation: a baseline knob, an effect parameter, or a run's ambient.
struct Free {
  enum Kind { kBase, kEffect, kAmbient, kRunGain } kind;
  int index;
  std::string param;  ///< effect parameter name
  bool log;
  double prior_center = 0.0;  ///< internal units
  double prior_sigma = 0.0;   ///< 0 = none
};

class Engine {
 public:
  Engine(const sim::Trace& data, const GyroConfig& nominal, const DiagnoseOptions& o)
      : nominal_(nominal), o_(o), runs_(diagnosis::Prepare(data, nominal, o)), knobs_(BaselineKnobs(nominal)),
        noise_(diagnosis::ScoreBlockNoise(runs_)), solver_(diagnosis::SolverForData(noise_)) {
    n_nodes_ = static_cast<int>(nominal.network.nodes.size());
    has_bias_ = std::all_of(runs_.begin(), runs_.end(), [](const PreparedRun& p) { return p.bias_col >= 0; });
    has_logged_ambient_ = std::any_of(runs_.begin(), runs_.end(), [](const PreparedRun& p) { return p.ambient_known; });
    for (size_t r = 0; r < runs_.size(); ++r) {
      const bool fit = o.fit_runs.empty() ||
                       std::find(o.fit_runs.begin(), o.fit_runs.end(), runs_[r].run->id) != o.fit_runs.end();
      (fit ? fit_ : held_).push_back(static_cast<int>(r));
    }
    for (const auto& id : o.fit_runs) data.FindRun(id);
    if (fit_.empty()) throw InputError("diagnose: no runs to fit on");
    if (held_.empty() && fit_.size() == 1) {
      // One run: held out in time (SPEC section 6). It is cut into equal pieces; the model is
      // fitted on the even ones and predicts the odd ones, simulated on from power-on.
      diagnosis::SplitRun split = diagnosis::SplitInTime(runs_[static_cast<size_t>(fit_.front())], o.single_run_pieces);
      split_note_ = std::move(split.note);
      runs_ = {std::move(split.fit), std::move(split.held)};
      fit_ = {0};
      held_ = {1};
    }
    model_.base.resize(knobs_.size());
    for (size_t i = 0; i < knobs_.size(); ++i) model_.base[i] = knobs_[i].nominal;
    model_.ambient.resize(runs_.size());
    if (o.per_run_source_gains)
      model_.run_gain.assign(runs_.size(), std::vector<double>(nominal.network.sources.size(), 1.0));
    for (size_t r = 0; r < runs_.size(); ++r) {
      // Unknown ambient: start at the first reading of the sensors after a soak.
      double s = 0.0;
      int c = 0;
      for (int col : runs_[r].sensor_col)
        if (col >= 0) s += runs_[r].run->columns[col][0], ++c;
      model_.ambient[r] = s / c;
    }
    for (size_t r = 0; r < runs_.size(); ++r) {
      const auto& t = runs_[r].run->t_s;
      const auto blocks = Blocks(t, runs_[r].fit_block_s, runs_[r].sample_period_s);
      std::vector<double> mids;
      for (const auto& b : blocks) mids.push_back(BlockMean(t, b));
      thermal_blocks_.emplace_back();
      block_times_.emplace_back();
      block_spans_.emplace_back();
      for (size_t i = 0; i < blocks.size(); ++i) {
        if (!runs_[r].Counts(t[blocks[i].first])) continue;
        thermal_blocks_.back().push_back(blocks[i]);
        block_times_.back().push_back(mids[i]);
        block_spans_.back().push_back(TimesOf(t, blocks[i]));
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
      const int amb = runs_[r].run->Find("T_amb");
      if (amb >= 0) {
        const auto& column = runs_[r].run->columns[amb];
        std::vector<std::pair<double, double>> pts = {{t.front(), column.front()}};
        for (const auto& b : Blocks(t, std::max(1.0, runs_[r].sample_period_s), runs_[r].sample_period_s)) {
          const double mid = BlockMean(t, b);
          if (mid > pts.back().first) pts.emplace_back(mid, BlockMean(column, b));
        }
        if (t.back() > pts.back().first) pts.emplace_back(t.back(), column.back());
        // Never beyond the score-block noise itself: where a record's nonzero second differences
        // are mostly its corners (60 s samples of an exact ramp), PointNoise measures them.
        const double floor = std::isfinite(noise_) ? 0.1 * noise_ : 0.0, cap = std::isfinite(noise_) ? noise_ : 0.0;
        const double tolerance = std::max(floor, std::min(3.0 * diagnosis::PointNoise(pts), cap));
        runs_[r].ambient = Profile::Table(sim::SimplifyPolyline(pts, tolerance));
      }
    }
    RequireScoreBlocks();
    const double white = 60.0 * nominal.noise.arw_deg_per_sqrt_h / std::sqrt(runs_.front().fit_block_s);
    // A noise-free gyro file still needs a scale for its prior: 1e-6 °/h, far below any
    // gyro's noise, keeps the prior from deciding anything the data can.
    bias_block_noise_ = std::max(std::hypot(white, 0.664 * nominal.noise.bias_instability_dph), 1e-6);
  }

  Diagnosis Run();

  /// Stage 3: the calibrated baseline model, the channel variances it weighs residuals with,
  /// and its summary.
  struct Calibration {
    Model model;
    std::vector<double> channel_var;
    CalibrationSummary summary;
  };
  Calibration Calibrate() const;

 private:
  /// Scores and held-out RMS are on score blocks (BlockLayout: whole fit blocks of a run in a
  /// row): data whose scored runs hold none cannot be diagnosed.
  void RequireScoreBlocks() const {
    size_t blocks = 0;
    std::vector<std::string> labels;
    for (int r : Scored()) {
      blocks += thermal_blocks_[static_cast<size_t>(r)].size() / static_cast<size_t>(runs_[static_cast<size_t>(r)].fit_blocks_per_score);
      labels.push_back(runs_[static_cast<size_t>(r)].label);
    }
    if (blocks == 0) {
      const PreparedRun& p = runs_[static_cast<size_t>(Scored().front())];
      const std::string& file = runs_.front().run->source;
      throw InputError(fmt::format("diagnose: {}the scored data ({}) hold no {:g} s score block of {:g} s fit blocks in a "
                                   "row; give longer or more runs",
                                   file.empty() ? "" : file + ": ", fmt::join(labels, "; "), p.score_block_s(), p.fit_block_s));
    }
  }

  // ---- thermal ------------------------------------------------------------------------------
  std::vector<Prediction> SimulateAll(const Model& m, const std::vector<int>& which) const {
    const GyroConfig g = Build(nominal_, knobs_, m);
    std::vector<Prediction> out(runs_.size());
    for (int r : which) {
      const int q = runs_[r].nuisance;
      if (m.run_gain.empty()) {
        out[r] = Simulate(g, runs_[r], block_spans_[r], m.ambient[q], n_nodes_, solver_);
        continue;
      }
      GyroConfig gr = g;  // this run's board: its own heater gains
      for (size_t s = 0; s < gr.network.sources.size(); ++s)
        gr.network.sources[s].gain *= m.run_gain[q][s];
      out[r] = Simulate(gr, runs_[r], block_spans_[r], m.ambient[q], n_nodes_, solver_);
    }
    return out;
  }

  /// Thermal residuals (prediction - data) on fit blocks, per run and sensor.
  std::vector<std::vector<std::vector<double>>> ThermalResiduals(const std::vector<Prediction>& pred,
                                                                 const std::vector<int>& which) const {
    std::vector<std::vector<std::vector<double>>> res(runs_.size());
    for (int r : which) {
      const auto& p = runs_[r];
      res[r].resize(nominal_.sensors.size());
      for (size_t s = 0; s < nominal_.sensors.size(); ++s) {
        if (p.sensor_col[s] < 0) continue;
        const Eigen::VectorXd meas = BlockMeans(p.run->columns[p.sensor_col[s]], r);
        for (Eigen::Index i = 0; i < meas.size(); ++i) res[r][s].push_back(pred[r].sensor[s][static_cast<size_t>(i)] - meas[i]);
      }
    }
    return res;
  }

  /// a - b, run by run and channel by channel.
  static std::vector<std::vector<std::vector<double>>> Difference(std::vector<std::vector<std::vector<double>>> a,
                                                                  const std::vector<std::vector<std::vector<double>>>& b) {
    for (size_t r = 0; r < a.size(); ++r)
      for (size_t s = 0; s < a[r].size(); ++s)
        for (size_t i = 0; i < a[r][s].size(); ++i) a[r][s][i] -= b[r][s][i];
    return a;
  }

  /// Sum over runs and channels of squared thermal residuals / channel variance (°C², per
  /// gyro sensor: ChannelVariances).
  static double ThermalChi2(const std::vector<std::vector<std::vector<double>>>& res, const std::vector<int>& which,
                            const std::vector<double>& channel_var) {
    double chi2 = 0.0;
    for (int r : which)
      for (size_t s = 0; s < res[r].size(); ++s)
        for (double v : res[r][s]) chi2 += v * v / channel_var[s];
    return chi2;
  }

  /// Per gyro sensor, the mean squared fit-block residual over the fit runs (°C²), floored at
  /// (0.5 mK)²: a perfect model must not get infinite weight. A channel no fit run has keeps
  /// the unit weight's 1e-4 °C² (it has no residual to weigh).
  std::vector<double> ChannelVariances(const std::vector<std::vector<std::vector<double>>>& res) const {
    std::vector<double> var(nominal_.sensors.size(), kUnitChannelVar);
    for (size_t s = 0; s < nominal_.sensors.size(); ++s) {
      double ssr = 0.0;
      int n = 0;
      for (int r : fit_)
        for (double v : res[r][s]) ssr += v * v, ++n;
      if (n > 0) var[s] = std::max(ssr / n, 2.5e-7);
    }
    return var;
  }
  /// The weights of the first calibration pass, before any residual is known: (10 mK)².
  static constexpr double kUnitChannelVar = 1e-4;

  /// Sum of squared score-block means of one channel's fit-block residuals in run r; adds
  /// their count to *n when given.
  double ScoreSsr(const std::vector<double>& residuals, int r, int* n = nullptr) const {
    double ssr = 0.0;
    for (double mean : ToScoreBlocks(Eigen::Map<const Eigen::VectorXd>(residuals.data(), static_cast<Eigen::Index>(residuals.size())), r)) {
      ssr += mean * mean;
      if (n) ++*n;
    }
    return ssr;
  }

  /// ScoreSsr over runs and channels (°C²): the held-out RMS of SPEC section 6 comes from it,
  /// on the scale the bias uses too.
  double ThermalScoreSsr(const std::vector<std::vector<std::vector<double>>>& res, const std::vector<int>& which) const {
    double ssr = 0.0;
    for (int r : which)
      for (const auto& channel : res[r]) ssr += ScoreSsr(channel, r);
    return ssr;
  }

  void SetOne(Model& m, const Free& f, double x) const {
    const double v = f.log ? std::exp(x) : x;
    if (f.kind == Free::kBase) m.base[f.index] = v;
    if (f.kind == Free::kEffect) m.effects[f.index].parameters[f.param] = v;
    if (f.kind == Free::kAmbient) m.ambient[f.index] = v;
    if (f.kind == Free::kRunGain) m.run_gain[f.index][std::stoul(f.param)] = v;
  }

  void SetFree(Model& m, const std::vector<Free>& free, const double* x) const {
    for (size_t i = 0; i < free.size(); ++i) SetOne(m, free[i], x[i]);
  }

  std::vector<double> GetFree(const Model& m, const std::vector<Free>& free) const {
    std::vector<double> x;
    for (const auto& f : free) {
      double v = 0.0;
      if (f.kind == Free::kBase) v = m.base[f.index];
      if (f.kind == Free::kEffect) v = m.effects[f.index].parameters.at(f.param);
      if (f.kind == Free::kAmbient) v = m.ambient[f.index];
      if (f.kind == Free::kRunGain) v = m.run_gain[f.index][std::stoul(f.param)];
      x.push_back(f.log ? std::log(v) : v);
    }
    return x;
  }

  /// What one least-squares pass reports (Ceres' Summary, the parts the stages use).
  struct FitSummary {
    bool usable = true;  ///< Ceres' IsSolutionUsable; nothing to fit is usable
    double initial_cost = 0.0, final_cost = 0.0;
    int iterations = 0;
  };

  /// Least squares of the thermal residuals over `which` runs for the free parameters, each
  /// residual weighted by 1 / sqrt(channel_var) of its sensor (°C², ChannelVariances). The
  /// model is updated only when the result is usable (not when the simulation failed at the
  /// start point).
  FitSummary FitThermal(Model& m, const std::vector<Free>& free, const std::vector<int>& which,
                        const std::vector<double>& channel_var, int max_iterations, Eigen::MatrixXd* jtj_out = nullptr) const {
    if (free.empty()) return {};
    // Parameter blocks: the shared parameters (knobs, effect parameters) and, per run, its own
    // nuisances (ambient, heater gains). A run's residuals depend on the shared block and its
    // own only, so each run is one residual block: a numeric Jacobian re-simulates one run per
    // parameter instead of every run.
    std::vector<size_t> shared;
    std::map<int, std::vector<size_t>> own;  // run -> indices into free
    for (size_t i = 0; i < free.size(); ++i) {
      const bool per_run = free[i].kind == Free::kAmbient || free[i].kind == Free::kRunGain;
      (per_run ? own[free[i].index] : shared).push_back(i);
    }
    const std::vector<double> x0 = GetFree(m, free);
    auto values = [&](const std::vector<size_t>& idx) {
      std::vector<double> v;
      for (size_t i : idx) v.push_back(x0[i]);
      return v;
    };
    std::vector<double> xs = values(shared);
    std::map<int, std::vector<double>> xr;
    for (const auto& [r, idx] : own) xr[r] = values(idx);

    struct RunResiduals {
      const Engine* e;
      const Model* base;
      const std::vector<Free>* free;
      std::vector<const std::vector<size_t>*> blocks;  // free indices of each parameter block
      int run;
      const std::vector<double>* channel_var;
      bool operator()(double const* const* params, double* residuals) const {
        Model m = *base;
        for (size_t b = 0; b < blocks.size(); ++b)
          for (size_t j = 0; j < blocks[b]->size(); ++j) e->SetOne(m, (*free)[(*blocks[b])[j]], params[b][j]);
        try {
          const std::vector<int> one = {run};
          const auto res = e->ThermalResiduals(e->SimulateAll(m, one), one);
          size_t k = 0;
          for (size_t s = 0; s < res[run].size(); ++s)
            for (double v : res[run][s]) residuals[k++] = v / std::sqrt((*channel_var)[s]);
          // A wild trial point (an overflowing log-parameter) is a failed evaluation, not a
          // NaN that Ceres would have to be told about.
          for (size_t i = 0; i < k; ++i)
            if (!std::isfinite(residuals[i])) return false;
          return true;
        } catch (const std::exception&) {
          return false;  // e.g. CVODE failure at a wild trial point: Ceres shrinks the step
        }
      }
    };
    const Model base = m;
    ceres::Problem problem;
    if (!xs.empty()) problem.AddParameterBlock(xs.data(), static_cast<int>(xs.size()));
    for (int r : which)
      if (xr.count(r)) problem.AddParameterBlock(xr[r].data(), static_cast<int>(xr[r].size()));
    // Forward differences: one simulation per parameter instead of central's two
    // (CalibrationOptions::relative_step).
    ceres::NumericDiffOptions diff;
    diff.relative_step_size = o_.calibration.relative_step;
    for (int r : which) {
      int n_res = 0;
      for (size_t s = 0; s < nominal_.sensors.size(); ++s)
        if (runs_[r].sensor_col[s] >= 0) n_res += static_cast<int>(thermal_blocks_[r].size());
      RunResiduals f{this, &base, &free, {}, r, &channel_var};
      std::vector<double*> blocks;
      if (!xs.empty()) f.blocks.push_back(&shared), blocks.push_back(xs.data());
      if (xr.count(r)) f.blocks.push_back(&own.at(r)), blocks.push_back(xr[r].data());
      if (n_res == 0 || blocks.empty()) continue;
      std::vector<int> sizes;
      for (const auto* idx : f.blocks) sizes.push_back(static_cast<int>(idx->size()));
      auto* cost = new ceres::DynamicNumericDiffCostFunction<RunResiduals, ceres::FORWARD>(
          new RunResiduals(std::move(f)), ceres::TAKE_OWNERSHIP, diff);
      for (int size : sizes) cost->AddParameterBlock(size);
      cost->SetNumResiduals(n_res);
      problem.AddResidualBlock(cost, nullptr, blocks);
    }
    // Priors (log-normal on knobs and gains): (x - center) / sigma on each block that has them.
    auto add_prior = [&](const std::vector<size_t>& idx, std::vector<double>& x) {
      std::vector<size_t> with;
      for (size_t j = 0; j < idx.size(); ++j)
        if (free[idx[j]].prior_sigma > 0.0) with.push_back(j);
      if (with.empty()) return;
      ceres::Matrix A = ceres::Matrix::Zero(static_cast<Eigen::Index>(with.size()), static_cast<Eigen::Index>(idx.size()));
      ceres::Vector b = ceres::Vector::Zero(static_cast<Eigen::Index>(idx.size()));
      for (size_t k = 0; k < with.size(); ++k) {
        const Free& f = free[idx[with[k]]];
        A(static_cast<Eigen::Index>(k), static_cast<Eigen::Index>(with[k])) = 1.0 / f.prior_sigma;
        b[static_cast<Eigen::Index>(with[k])] = f.prior_center;
      }
      problem.AddResidualBlock(new ceres::NormalPrior(A, b), nullptr, x.data());
    };
    if (!xs.empty()) add_prior(shared, xs);
    for (int r : which)
      if (xr.count(r)) add_prior(own.at(r), xr[r]);

    ceres::Solver::Options opts;
    opts.linear_solver_type = ceres::DENSE_QR;
    opts.max_num_iterations = max_iterations;
    opts.logging_type = ceres::SILENT;
    opts.function_tolerance = o_.calibration.function_tolerance;
    ceres::Solver::Summary summary;
    ceres::Solve(opts, &problem, &summary);
    FitSummary out{summary.IsSolutionUsable(), summary.initial_cost, summary.final_cost,
                   static_cast<int>(summary.iterations.size())};
    if (!out.usable) return out;
    for (size_t j = 0; j < shared.size(); ++j) SetOne(m, free[shared[j]], xs[j]);
    for (const auto& [r, idx] : own)
      for (size_t j = 0; j < idx.size(); ++j) SetOne(m, free[idx[j]], xr[r][j]);
    if (jtj_out) {
      // Columns in the order the blocks were added: the shared block (knobs first) leads.
      ceres::CRSMatrix J;
      problem.Evaluate(ceres::Problem::EvaluateOptions(), nullptr, nullptr, nullptr, &J);
      Eigen::MatrixXd Jd = Eigen::MatrixXd::Zero(J.num_rows, J.num_cols);
      for (int row = 0; row < J.num_rows; ++row)
        for (int i = J.rows[row]; i < J.rows[row + 1]; ++i) Jd(row, J.cols[i]) = J.values[i];
      *jtj_out = Jd.transpose() * Jd;
    }
    return out;
  }

  std::vector<Free> BaselineFree(const std::vector<int>& which_ambient) const {
    std::vector<Free> f;
    for (size_t i = 0; i < knobs_.size(); ++i) {
      // A prior on every nominal knob: the gyro file's relative uncertainty (log units). It
      // keeps combinations the data cannot see (power vs coupling from one ambient) near
      // nominal, and a well-known gyro from absorbing a small missing effect.
      f.push_back({Free::kBase, static_cast<int>(i), "", true, std::log(knobs_[i].nominal),
                   nominal_.calibration_uncertainty});
    }
    for (const auto& a : AmbientFree(which_ambient)) f.push_back(a);
    return f;
  }

  /// Per-run nuisances: the ambient where it was not logged and, with per_run_source_gains,
  /// each data-driven source's gain (runs from different boards). Gains are relative to the
  /// global ones, so they get a prior of the gyro's relative uncertainty around 1.
  std::vector<Free> AmbientFree(const std::vector<int>& which) const {
    std::vector<Free> f;
    for (int r : which) {
      if (runs_[r].nuisance != r) continue;  // shares its run's, fitted with it
      if (!runs_[r].ambient_known) f.push_back({Free::kAmbient, r, "", false});
      if (model_.run_gain.empty()) continue;
      for (size_t s = 0; s < nominal_.network.sources.size(); ++s)
        if (nominal_.network.sources[s].driven_by_data)
          f.push_back({Free::kRunGain, r, std::to_string(s), true, 0.0, nominal_.calibration_uncertainty});
    }
    return f;
  }

  // ---- bias ---------------------------------------------------------------------------------
  using BiasDesign = diagnosis::BiasDesign;

  /// The gyro file's values of the baseline bias coefficients, in BiasRegressors' columns (dT,
  /// dT², and per Langmuir gradient G and G dT), as a prior with a sd of 100 % of each
  /// (order-of-magnitude knowledge: the files mark them [est]): it holds what the data cannot
  /// see, as the thermal knobs' prior does. Two discharge legs built alike have gradients the
  /// data cannot tell apart; fitted freely, their coefficients came out at -8 and +8.4 °/h/°C
  /// (sum 0.45, the truth's) and predicted a held-out run 6x worse than the noise. The dT
  /// column also carries what is linear in the bias node's temperature in the Langmuir
  /// current term and the path-length control. A zero nominal has no prior (free).
  void BaselinePrior(const GyroConfig& g, Eigen::Index cols, BiasDesign* d) const {
    const std::vector<double> mean = sim::BaselineCoefficients(g.bias);
    d->prior_mean = Eigen::VectorXd::Zero(cols);
    d->prior_weight = Eigen::VectorXd::Zero(cols);
    for (size_t j = 0; j < mean.size(); ++j) {
      if (mean[j] == 0.0) continue;
      d->prior_mean[static_cast<Eigen::Index>(j)] = mean[j];
      d->prior_weight[static_cast<Eigen::Index>(j)] = bias_block_noise_ / std::abs(mean[j]);
    }
  }

  /// Global bias regressors on fit blocks for one run: the baseline physics
  /// (sim::BaselineRegressors) plus `extra` columns.
  Eigen::MatrixXd BiasRegressors(const GyroConfig& g, const Prediction& p, int r,
                                 const std::vector<std::function<double(const Prediction&, size_t, int)>>& extra) const {
    const auto nb = static_cast<Eigen::Index>(p.T.cols());
    const Eigen::Index base = sim::NumBaselineRegressors(g.bias);
    Eigen::MatrixXd X(nb, base + static_cast<Eigen::Index>(extra.size()));
    for (Eigen::Index i = 0; i < nb; ++i) {
      sim::BaselineRegressors(g.bias, p.T.col(i), X.row(i).head(base));
      Eigen::Index c = base;
      for (const auto& f : extra) X(i, c++) = f(p, static_cast<size_t>(i), r);
    }
    return X;
  }

  /// Means of `v` (a column of run r, or one as long) over run r's fit blocks.
  Eigen::VectorXd BlockMeans(const std::vector<double>& v, int r) const {
    Eigen::VectorXd y(static_cast<Eigen::Index>(thermal_blocks_[r].size()));
    for (size_t i = 0; i < thermal_blocks_[r].size(); ++i) y[static_cast<Eigen::Index>(i)] = BlockMean(v, thermal_blocks_[r][i]);
    return y;
  }

  Eigen::VectorXd BiasData(int r) const { return BlockMeans(runs_[r].run->columns[runs_[r].bias_col], r); }

  Eigen::VectorXd FitBias(const BiasDesign& d, const std::vector<int>& train) const { return diagnosis::FitBias(d, train); }
  Eigen::VectorXd BiasResidual(const BiasDesign& d, const Eigen::VectorXd& beta, int r) const {
    return diagnosis::BiasResidual(d, beta, r);
  }
  /// Held-out bias residuals per run (diagnosis::HeldOutBias over this data's split).
  std::vector<Eigen::VectorXd> HeldOutBias(const BiasDesign& d) const { return diagnosis::HeldOutBias(d, fit_, held_); }

  std::vector<int> Scored() const { return held_.empty() ? fit_ : held_; }

  /// Score-block means of run r's fit-block residuals.
  std::vector<double> ToScoreBlocks(const Eigen::Ref<const Eigen::VectorXd>& e, int r) const {
    const int per = runs_[static_cast<size_t>(r)].fit_blocks_per_score;
    std::vector<double> out;
    for (Eigen::Index i = 0; i + per <= e.size(); i += per) out.push_back(e.segment(i, per).mean());
    return out;
  }

  /// Score-block means of the scored runs' residuals, summarised for scoring.
  diagnosis::ResidualFit ScoreBias(const std::vector<Eigen::VectorXd>& res) const {
    std::vector<std::vector<double>> series;
    for (int r : Scored()) series.push_back(ToScoreBlocks(res[r], r));
    return diagnosis::Summarise(series);
  }

  // ---- steps ----------------------------------------------------------------------------------
  /// Held-out RMS of score-block residuals per channel and for the bias.
  Metrics Measure(const Model& m) const;

  Model model_;
  const GyroConfig& nominal_;
  DiagnoseOptions o_;
  std::vector<PreparedRun> runs_;
  std::vector<BaseKnob> knobs_;
  double noise_;               // ScoreBlockNoise
  /// Noise of a fit-block mean of the bias by the gyro file's noise terms (°/h): ARW over the
  /// first run's fit block and the flicker floor; what BaselinePrior weighs against.
  double bias_block_noise_ = 0.0;
  sim::SolverOptions solver_;  // CVODE tolerances for this data (SolverForData)
  /// The bias candidates' score a null dataset reaches, replicate by replicate (NullBootstrap).
  NullBootstrap NullBiasThreshold(const std::vector<Prediction>& pred) const;
  /// What the report says of it: the threshold, the replicates, how many let some candidate
  /// pass the held-out test.
  std::string NullBootstrapNote(const NullBootstrap& null) const;
  int n_nodes_ = 0;
  bool has_bias_ = false;
  std::vector<int> fit_, held_;
  std::string split_note_;  ///< how a single run was split in time, if it was
  bool has_logged_ambient_ = false;  ///< some run logs T_amb
  std::vector<std::vector<std::pair<size_t, size_t>>> thermal_blocks_;
  std::vector<std::vector<double>> block_times_;       ///< per run, the mean time of each counted fit block
  std::vector<std::vector<BlockTimes>> block_spans_;  ///< per run, each counted fit block's sample times

 public:
  std::vector<int> All() const {
    std::vector<int> a(runs_.size());
    std::iota(a.begin(), a.end(), 0);
    return a;
  }
  std::vector<Candidate> ThermalCandidates(const Model& m, const std::vector<Prediction>& pred, double chi2_base,
                                           const std::vector<double>& channel_var, std::vector<Model>* models) const;
  using Extra = std::function<double(const Prediction&, size_t, int)>;
  /// Every bias effect on every target as a candidate, scored on the data's bias or, given
  /// `bias_data`, on those fit-block means instead (a null replicate).
  std::vector<Candidate> BiasCandidates(const Model& m, const std::vector<Prediction>& pred,
                                        const std::vector<Extra>& accepted, const std::set<std::string>& taken,
                                        const std::vector<Eigen::VectorXd>* bias_data,
                                        std::vector<std::vector<Extra>>* extras) const;
  /// The bias regression of model m: per run, the baseline and `extra` regressors on fit
  /// blocks and, as y, the fit-block means of the data's bias or, given `bias_data` (per run,
  /// one value per counted fit block, °/h), those instead.
  BiasDesign Design(const Model& m, const std::vector<Prediction>& pred,
                    const std::vector<std::function<double(const Prediction&, size_t, int)>>& extra,
                    const std::vector<Eigen::VectorXd>* bias_data = nullptr) const {
    BiasDesign d;
    const GyroConfig g = Build(nominal_, knobs_, m);
    d.X.resize(runs_.size());
    d.y.resize(runs_.size());
    for (size_t r = 0; r < runs_.size(); ++r) {
      d.X[r] = BiasRegressors(g, pred[r], static_cast<int>(r), extra);
      d.y[r] = bias_data ? (*bias_data)[r] : BiasData(static_cast<int>(r));
    }
    BaselinePrior(g, d.X.front().cols(), &d);
    return d;
  }
};

std::vector<Candidate> Engine::ThermalCandidates(const Model& m, const std::vector<Prediction>& pred, double chi2_base,
                                                 const std::vector<double>& channel_var, std::vector<Model>* models) const {
  const GyroConfig g = Build(nominal_, knobs_, m);
  const std::vector<int> all = All();
  const auto base_res = ThermalResiduals(pred, all);
  std::vector<Candidate> cands;
  // Every thermal and sensor effect of the catalog on every target, each at its start; sensor
  // effects channel by channel (lag and offset on T1, then on T2, ...), the order of the
  // candidate list.
  std::set<std::string> channels;
  for (const auto& p : runs_)
    for (size_t s = 0; s < g.sensors.size(); ++s)
      if (p.sensor_col[s] >= 0) channels.insert(g.sensors[s].channel);
  const sim::TargetSpace space{g, n_nodes_, {channels.begin(), channels.end()}};
  std::vector<sim::EffectSpec> specs, sensor_specs;
  for (const auto& effect : sim::Effects()) {
    if (effect->kind() == sim::EffectKind::kBias) continue;
    auto& to = effect->kind() == sim::EffectKind::kSensor ? sensor_specs : specs;
    for (const auto& target : effect->Targets(space)) to.push_back({effect->name(), target, effect->Start()});
  }
  std::stable_sort(sensor_specs.begin(), sensor_specs.end(),
                   [](const sim::EffectSpec& a, const sim::EffectSpec& b) { return a.target < b.target; });
  specs.insert(specs.end(), sensor_specs.begin(), sensor_specs.end());
  // Skip what the model already has.
  std::vector<sim::EffectSpec> fresh;
  for (const auto& s : specs) {
    bool dup = false;
    for (const auto& e : m.effects)
      if (e.name == s.name && CanonicalTarget(nominal_, e.name, e.target) == CanonicalTarget(nominal_, s.name, s.target))
        dup = true;
    if (!dup) fresh.push_back(s);
  }

  // Flatten residuals (normalised by channel noise) in a fixed order.
  auto flatten = [&](const std::vector<std::vector<std::vector<double>>>& res) {
    std::vector<double> v;
    for (int r : fit_)
      for (size_t s = 0; s < res[r].size(); ++s)
        for (double x : res[r][s]) v.push_back(x / std::sqrt(channel_var[s]));
    return Eigen::Map<Eigen::VectorXd>(v.data(), static_cast<Eigen::Index>(v.size())).eval();
  };
  const Eigen::VectorXd r0 = flatten(base_res);
  // Jacobian of the calibrated baseline knobs (forward differences, 1e-3 in log units): the
  // screening projects it out, so a candidate is credited only for what recalibrating the
  // nominal network could not explain (a Lagrange-multiplier, or score, test).
  const std::vector<Free> base_free = BaselineFree(fit_);
  Eigen::MatrixXd J0(r0.size(), static_cast<Eigen::Index>(base_free.size()));
  {
    const std::vector<double> x0 = GetFree(m, base_free);
    for (size_t i = 0; i < base_free.size(); ++i) {
      std::vector<double> x = x0;
      x[i] += 1e-3;
      Model trial = m;
      SetFree(trial, base_free, x.data());
      J0.col(static_cast<Eigen::Index>(i)) = (flatten(ThermalResiduals(SimulateAll(trial, fit_), fit_)) - r0) / 1e-3;
    }
  }
  const Eigen::MatrixXd Q0 = diagnosis::KnobBasis(J0);

  struct Screened {
    sim::EffectSpec spec;
    double gain;
    double step;  // multiple of the screening parameters
  };
  std::vector<Screened> screened;
  for (const auto& spec : fresh) {
    Model trial = m;
    trial.effects.push_back(spec);
    Eigen::VectorXd jc;
    try {
      jc = flatten(ThermalResiduals(SimulateAll(trial, fit_), fit_)) - r0;
    } catch (const std::exception&) {
      continue;
    }
    const auto test = diagnosis::ScoreTest(Q0, jc, r0);
    if (!test) continue;
    // A size that cannot be negative (a mass, a conductance) gains nothing from a negative step.
    const bool signed_ok = sim::RequireEffect(spec.name).SizeIsSigned() || test->step > 0.0;
    screened.push_back({spec, signed_ok ? test->gain : 0.0, test->step});
  }
  std::sort(screened.begin(), screened.end(), [](const Screened& a, const Screened& b) { return a.gain > b.gain; });

  // Full refits of the best few: the effect's parameters together with every baseline knob,
  // so that what the calibration absorbed can move back into the effect.
  for (size_t i = 0; i < screened.size(); ++i) {
    Candidate c;
    c.cause = screened[i].spec.name;
    c.target = screened[i].spec.target;
    c.kind = "thermal";
    Model trial = m;
    sim::EffectSpec spec = screened[i].spec;
    const sim::Effect& effect = sim::RequireEffect(spec.name);
    if (static_cast<int>(i) < o_.thermal_refits && screened[i].gain > 0.0) {
      // The screening step scales the effect's size; its shape parameters stay at their start.
      for (auto& [k, v] : spec.parameters) {
        const sim::EffectParameter& param = *effect.FindParameter(k);
        if (param.fit != sim::EffectParameter::Fit::kSize) continue;
        v *= std::clamp(screened[i].step, param.positive ? 0.05 : -1e3, 1e3);
      }
      trial.effects.push_back(spec);
      const int e = static_cast<int>(trial.effects.size()) - 1;
      std::vector<Free> effect_free;
      for (const auto& [k, v] : spec.parameters) {
        const sim::EffectParameter& param = *effect.FindParameter(k);
        if (param.fit == sim::EffectParameter::Fit::kFixed) continue;
        Free f{Free::kEffect, e, k, param.positive};
        if (param.prior_factor > 0.0) {
          // e.g. a missing mass's capacity, which trades against its conductance.
          f.prior_center = std::log(param.start);
          f.prior_sigma = std::log(param.prior_factor);
        }
        effect_free.push_back(f);
      }
      // First the effect alone, from the screening step; a pass that cannot start leaves the
      // screening step, and the joint fit below decides.
      FitThermal(trial, effect_free, fit_, channel_var, 20);
      std::vector<Free> free = base_free;
      free.insert(free.end(), effect_free.begin(), effect_free.end());
      if (!FitThermal(trial, free, fit_, channel_var, 30).usable) continue;
      const auto trial_res = ThermalResiduals(SimulateAll(trial, fit_), fit_);
      const auto chi2_fit = ThermalChi2(trial_res, fit_, channel_var);
      // Held-out: with the knobs of the joint fit, the effect parameters fitted on one half of
      // the runs predict the other half (or the held-out runs).
      double held_base = 0.0, held_ext = 0.0;
      std::vector<std::vector<int>> folds;
      if (!held_.empty()) {
        folds = {held_};
      } else if (fit_.size() >= 2) {
        std::vector<int> a, b;
        for (size_t q = 0; q < fit_.size(); ++q) (q % 2 ? b : a).push_back(fit_[q]);
        folds = {a, b};
      } else {
        folds = {fit_};
      }
      for (const auto& test : folds) {
        std::vector<int> train;
        for (int q : fit_)
          if (std::find(test.begin(), test.end(), q) == test.end()) train.push_back(q);
        // A fold whose pass cannot start keeps the joint fit's values, which can only flatter
        // the held-out score by what the test runs taught it; the other fold and the score
        // test stand beside it.
        Model fold = trial;
        if (!train.empty() && held_.empty()) FitThermal(fold, effect_free, train, channel_var, 20);
        FitThermal(fold, AmbientFree(test), test, channel_var, 20);  // nuisance ambients of the test runs
        held_ext += ThermalScoreSsr(ThermalResiduals(SimulateAll(fold, test), test), test);
        held_base += ThermalScoreSsr(base_res, test);
      }
      c.parameters = effect.Reported(trial.effects.back().parameters);
      const double k = static_cast<double>(c.parameters.size());
      c.score = (chi2_base - chi2_fit) - k * std::log(static_cast<double>(r0.size()));
      c.heldout_rms_ratio = diagnosis::HeldOutRmsRatio(held_base, held_ext);
      // The gain must come from the effect: the fitted effect, taken out again with the knobs
      // as they are, must move the prediction by at least what acceptance asks of a score
      // (its noncentrality, sum of squared changes in noise units). A refit that drove the
      // parameter to nothing (a radiating area of 6e-220 m² was accepted, issue #10) gained
      // by moving the knobs alone, which is the calibration's business, not a cause.
      Model without = trial;
      without.effects.pop_back();
      if (ThermalChi2(Difference(trial_res, ThermalResiduals(SimulateAll(without, fit_), fit_)), fit_, channel_var) <
          o_.min_score)
        c.kind = "thermal (no effect)";
      models->push_back(trial);
    } else {
      // Screened only: the linearised gain stands in for the score; no held-out gain claimed.
      c.score = screened[i].gain - std::log(static_cast<double>(r0.size()));
      c.heldout_rms_ratio = 1.0;
      c.kind = "thermal (screened)";
      models->push_back(m);
    }
    cands.push_back(c);
  }
  return cands;
}

std::vector<Candidate> Engine::BiasCandidates(const Model& m, const std::vector<Prediction>& pred,
                                              const std::vector<Extra>& accepted, const std::set<std::string>& taken,
                                              const std::vector<Eigen::VectorXd>* bias_data,
                                              std::vector<std::vector<Extra>>* extras) const {
  const GyroConfig g = Build(nominal_, knobs_, m);
  const BiasDesign base = Design(m, pred, accepted, bias_data);
  const diagnosis::ResidualFit base_fit = ScoreBias(HeldOutBias(base));
  // In-sample fit of the baseline for the information criterion, at the fit resolution: rate
  // and gradient terms differ only in transients of a few minutes, which 100 s means blur.
  auto in_sample = [&](const BiasDesign& d) {
    const Eigen::VectorXd beta = FitBias(d, fit_);
    std::vector<std::vector<double>> series;
    for (int r : fit_) {
      const Eigen::VectorXd e = BiasResidual(d, beta, r);
      series.emplace_back(e.data(), e.data() + e.size());
    }
    return std::make_pair(diagnosis::Summarise(series), beta);
  };
  const diagnosis::ResidualFit base_in = in_sample(base).first;

  // Every bias effect of the catalog on every target: its term at unit coefficient as an extra
  // regressor (the function the simulator's BiasModel calls).
  struct Option {
    std::string cause, target;
    std::vector<Extra> extra;
    std::function<std::map<std::string, double>(const Eigen::VectorXd&)> to_params;
  };
  std::vector<Option> options;
  const int first_extra = sim::NumBaselineRegressors(g.bias) + static_cast<int>(accepted.size());
  const sim::TargetSpace space{g, n_nodes_, {}};
  std::vector<const Eigen::MatrixXd*> tracks;
  for (const auto& p : pred) tracks.push_back(&p.T);
  for (const auto& effect : sim::Effects()) {
    if (effect->kind() != sim::EffectKind::kBias) continue;
    for (auto& reg : effect->Regressors(space, tracks)) {
      options.push_back({effect->name(), reg.target,
                         {[column = reg.column](const Prediction& p, size_t k, int r) {
                           return column(sim::NodeTrack{p.T, p.Tdot}, k, r);
                         }},
                         [first_extra, parameters = reg.parameters](const Eigen::VectorXd& beta) {
                           return parameters(beta[first_extra]);
                         }});
    }
  }

  std::vector<Candidate> cands;
  std::map<std::string, size_t> best_of;  // one candidate per (cause, target): the best range
  for (const auto& opt : options) {
    const std::string key = opt.cause + "|" + CanonicalTarget(nominal_, opt.cause, opt.target);
    if (taken.count(key)) continue;
    std::vector<Extra> all_extra = accepted;
    all_extra.insert(all_extra.end(), opt.extra.begin(), opt.extra.end());
    const BiasDesign d = Design(m, pred, all_extra, bias_data);
    const diagnosis::ResidualFit held = ScoreBias(HeldOutBias(d));
    const auto [fin, beta] = in_sample(d);
    Candidate c;
    c.cause = opt.cause;
    c.target = opt.target;
    c.kind = "bias";
    c.parameters = opt.to_params(beta);
    c.score = diagnosis::InformationGain(base_in, fin, static_cast<int>(opt.extra.size()));
    c.heldout_rms_ratio = diagnosis::HeldOutRmsRatio(base_fit.ssr, held.ssr);
    const auto it = best_of.find(key);
    if (it != best_of.end()) {
      if (cands[it->second].score >= c.score) continue;
      cands[it->second] = c;
      (*extras)[it->second] = opt.extra;
      continue;
    }
    best_of[key] = cands.size();
    cands.push_back(c);
    extras->push_back(opt.extra);
  }
  return cands;
}

NullBootstrap Engine::NullBiasThreshold(const std::vector<Prediction>& pred) const {
  // Parametric bootstrap (DIAGNOSIS.md, point 3): bias data made of the calibrated baseline's
  // fitted bias plus the gyro file's own noise (ARW, bias instability, quantization: the
  // simulator's GyroNoise), block-averaged like the data. The best acceptable bias candidate's
  // score on each replicate is what noise alone reaches; slow bias instability makes it far
  // above the white-noise information criterion for slowly varying regressors (hysteresis).
  const BiasDesign base = Design(model_, pred, {});
  const Eigen::VectorXd beta = FitBias(base, fit_);
  std::vector<double> best;
  for (int b = 0; b < o_.null_replicates; ++b) {
    std::vector<Eigen::VectorXd> y(runs_.size());
    for (size_t r = 0; r < runs_.size(); ++r) {
      sim::Rng rng(static_cast<uint64_t>(b) + 1, r);
      sim::GyroNoise noise(nominal_.noise, runs_[r].sample_period_s, rng);
      std::vector<double> n(runs_[r].run->size());
      for (double& v : n) v = noise.Sample(0.0);
      y[r] = base.X[r] * beta + BlockMeans(n, static_cast<int>(r));
    }
    std::vector<std::vector<Extra>> extras;
    double top = -std::numeric_limits<double>::infinity();
    for (const auto& c : BiasCandidates(model_, pred, {}, {}, &y, &extras))
      if (c.heldout_rms_ratio >= o_.min_heldout_ratio) top = std::max(top, c.score);
    best.push_back(top);
  }
  NullBootstrap out;
  out.replicates = static_cast<int>(best.size());
  // The largest of the replicates: with 40 of them, a null dataset beats it ~2.5 % of the time.
  out.threshold = diagnosis::NullThreshold(best, o_.min_score);
  out.replicate_scores = std::move(best);
  return out;
}

std::string Engine::NullBootstrapNote(const NullBootstrap& null) const {
  const auto& best = null.replicate_scores;
  const auto passed = std::count_if(best.begin(), best.end(), [](double v) { return std::isfinite(v); });
  return fmt::format("bias acceptance: score >= {:.1f}, the best bias candidate's score on {} null replicates "
                     "(calibrated model + the gyro file's noise; in {} of them some candidate also passed the held-out "
                     "test); the information criterion alone asks {:.0f}",
                     null.threshold, best.size(), passed, o_.min_score);
}

Metrics Engine::Measure(const Model& m) const {
  Metrics out;
  const std::vector<int> all = All();
  const auto pred = SimulateAll(m, all);
  const auto res = ThermalResiduals(pred, all);
  for (size_t s = 0; s < nominal_.sensors.size(); ++s) {
    double ssr = 0.0;
    int n = 0;
    for (int r : Scored())
      if (s < res[r].size()) ssr += ScoreSsr(res[r][s], r, &n);
    if (n > 0) out.temperature_rms_C[nominal_.sensors[s].channel] = std::sqrt(ssr / n);
  }
  if (has_bias_) out.bias_rms_dph = ScoreBias(HeldOutBias(Design(m, pred, {}))).rms();
  return out;
}

Engine::Calibration Engine::Calibrate() const {
  // Channel variances come from a first pass (unit weights), then the fit is repeated with
  // them; the held-out runs' nuisances follow with the knobs fixed.
  const CalibrationOptions& co = o_.calibration;
  Calibration out;
  out.model = model_;
  const std::vector<int> all = All();
  Eigen::MatrixXd jtj;
  const FitSummary first = FitThermal(out.model, BaselineFree(fit_), fit_,
                                      std::vector<double>(nominal_.sensors.size(), kUnitChannelVar), co.max_iterations);
  out.channel_var = ChannelVariances(ThermalResiduals(SimulateAll(out.model, all), all));
  const FitSummary second = FitThermal(out.model, BaselineFree(fit_), fit_, out.channel_var, co.max_iterations, &jtj);
  if (!second.usable) {
    throw NumericalError(fmt::format("diagnose: {}the calibration of the nominal gyro to the data failed (the simulation "
                                     "failed at the start point); check that the gyro file describes this data",
                                     runs_.front().run->source.empty() ? "" : runs_.front().run->source + ": "));
  }
  const FitSummary nuisance = FitThermal(out.model, AmbientFree(held_), held_, out.channel_var, co.nuisance_max_iterations);
  CalibrationSummary& s = out.summary;
  // A held-out run whose nuisance fit failed keeps its start ambient; its held-out RMS shows it.
  s.usable = second.usable;
  s.initial_cost = second.initial_cost;
  s.final_cost = second.final_cost;
  s.iterations = first.iterations + second.iterations + nuisance.iterations;
  s.prior_sd = nominal_.calibration_uncertainty;
  const auto k = static_cast<Eigen::Index>(knobs_.size());
  s.covariance = jtj.completeOrthogonalDecomposition().pseudoInverse().topLeftCorner(k, k);
  for (size_t i = 0; i < knobs_.size(); ++i) {
    const double nominal = knobs_[i].nominal, calibrated = out.model.base[i];
    const auto ii = static_cast<Eigen::Index>(i);
    s.knobs.push_back({knobs_[i].name, nominal, calibrated, std::log(calibrated / nominal) / s.prior_sd,
                       std::sqrt(std::max(0.0, s.covariance(ii, ii)))});
  }
  return out;
}

Diagnosis Engine::Run() {
  Diagnosis dx;
  dx.has_bias = has_bias_;
  dx.score_block_s = {std::numeric_limits<double>::infinity(), 0.0};
  for (const auto& p : runs_) {
    dx.score_block_s.first = std::min(dx.score_block_s.first, p.score_block_s());
    dx.score_block_s.second = std::max(dx.score_block_s.second, p.score_block_s());
  }
  if (!split_note_.empty()) dx.notes.push_back(split_note_);
  const std::vector<int> all = All();

  // 1. Calibrate the nominal thermal network (stage 3; its channel variances weigh every
  //    thermal fit and score from here on).
  const Calibration cal = Calibrate();
  model_ = cal.model;
  const std::vector<double>& channel_var = cal.channel_var;
  dx.calibration = cal.summary;
  {
    // Identifiability: which combinations of the knobs the data determine, and which are
    // left to the prior.
    const auto k = static_cast<Eigen::Index>(knobs_.size());
    std::vector<std::string> names;
    for (const auto& knob : knobs_) names.push_back(knob.name);
    dx.identifiability = diagnosis::AnalyseIdentifiability(cal.summary.covariance, names, nominal_.calibration_uncertainty);
    if (k >= 2) {
      dx.knob_correlations = diagnosis::CorrelationsGivenScale(cal.summary.covariance);
      dx.knob_names = names;
    }
    for (size_t i = 0; i < knobs_.size(); ++i) dx.calibrated[knobs_[i].name] = model_.base[i];
    for (size_t r = 0; r < runs_.size(); ++r)
      if (!runs_[r].ambient_known && runs_[r].nuisance == static_cast<int>(r))
        dx.calibrated["T_amb:" + runs_[r].run->id] = model_.ambient[r];
  }
  dx.baseline = Measure(model_);
  // Whiteness of the baseline residuals.
  {
    const auto pred = SimulateAll(model_, all);
    const auto res = ThermalResiduals(pred, all);
    for (size_t s = 0; s < nominal_.sensors.size(); ++s) {
      std::vector<double> pooled;
      for (int r : all)
        if (s < res[r].size()) pooled.insert(pooled.end(), res[r][s].begin(), res[r][s].end());
      if (!pooled.empty()) dx.ljung_box_p[nominal_.sensors[s].channel] = diagnosis::LjungBoxP(pooled, 10);
    }
    if (has_bias_) {
      const auto held = HeldOutBias(Design(model_, pred, {}));
      std::vector<double> pooled;
      for (int r : Scored()) pooled.insert(pooled.end(), held[r].data(), held[r].data() + held[r].size());
      dx.ljung_box_p["bias_dph"] = diagnosis::LjungBoxP(pooled, 10);
      // Steps (diagnosis::LargestStep), reported where they pass the threshold.
      for (int r : Scored()) {
        const auto step = diagnosis::LargestStep(held[r], block_times_[r], runs_[r].label);
        if (step && step->statistic > step->threshold) {
          dx.detected_steps.push_back(*step);
          dx.notes.push_back(diagnosis::StepNote(*step));
        }
      }
    }
  }
  Model baseline_model = model_;
  std::vector<std::function<double(const Prediction&, size_t, int)>> accepted_extra;

  // 3. Search, accept, repeat.
  dx.null_bootstrap.threshold = o_.min_score;
  if (has_bias_ && o_.null_replicates > 0) {
    dx.null_bootstrap = NullBiasThreshold(SimulateAll(model_, all));
    dx.notes.push_back(NullBootstrapNote(dx.null_bootstrap));
  }
  const double bias_threshold = dx.null_bootstrap.threshold;
  for (int step = 0; step < o_.max_steps; ++step) {
    const auto pred = SimulateAll(model_, all);
    const double chi2 = ThermalChi2(ThermalResiduals(pred, all), fit_, channel_var);
    std::vector<Model> models;
    std::vector<Candidate> cands = ThermalCandidates(model_, pred, chi2, channel_var, &models);
    std::vector<std::vector<std::function<double(const Prediction&, size_t, int)>>> extras(cands.size());
    if (has_bias_) {
      std::vector<std::vector<Extra>> bias_extras;
      std::set<std::string> taken;
      for (const auto& st : dx.steps) taken.insert(st.accepted.cause + "|" + CanonicalTarget(nominal_, st.accepted.cause, st.accepted.target));
      auto b = BiasCandidates(model_, pred, accepted_extra, taken, nullptr, &bias_extras);
      cands.insert(cands.end(), b.begin(), b.end());
      models.resize(cands.size(), model_);
      extras.insert(extras.end(), bias_extras.begin(), bias_extras.end());
    }
    // Stage 5: thermal causes are upstream, so a significant one is taken before any bias
    // candidate; exact twins by held-out RMS, then plausibility (diagnosis::Rank).
    const diagnosis::RankingRule rule = diagnosis::RankingRule::From(o_, bias_threshold);
    const std::vector<size_t> order = diagnosis::Rank(cands, rule);
    std::vector<Candidate> ranked;
    for (size_t i : order) ranked.push_back(cands[i]);
    if (step == 0) dx.first_candidates = ranked;
    if (ranked.empty() || !diagnosis::Significant(ranked.front(), rule)) break;
    const size_t best = order.front();
    DiagnosisStep st;
    st.accepted = cands[best];
    st.candidates = ranked;
    st.before = Measure(model_);
    st.ties = diagnosis::Ties(ranked, rule);
    if (!st.ties.empty()) st.notes.push_back(diagnosis::AmbiguityNote(ranked.front(), st.ties, has_logged_ambient_));
    if (st.accepted.kind == "thermal") {
      model_ = models[best];
      // Recalibrate the whole network with the new element.
      const sim::Effect& effect = sim::RequireEffect(st.accepted.cause);
      std::vector<Free> free = BaselineFree(fit_);
      for (const auto& [k, v] : effect.Reported(model_.effects.back().parameters))
        free.push_back({Free::kEffect, static_cast<int>(model_.effects.size()) - 1, k, effect.FindParameter(k)->positive});
      if (!FitThermal(model_, free, fit_, channel_var, o_.calibration.max_iterations).usable)
        st.notes.push_back("the recalibration with " + st.accepted.cause + " " + st.accepted.target +
                           " could not start; the candidate's own refit stands");
      FitThermal(model_, AmbientFree(held_), held_, channel_var, o_.calibration.nuisance_max_iterations);
      st.accepted.parameters = effect.Reported(model_.effects.back().parameters);
      st.after = Measure(model_);
    } else {
      // Bias effects enter the simulation model as effects with the fitted parameters.
      const sim::EffectSpec e{st.accepted.cause, st.accepted.target,
                              sim::RequireEffect(st.accepted.cause).FromReported(st.accepted.parameters)};
      // Residual gain with the matching regressor in the compensation model.
      const BiasDesign before = Design(model_, pred, accepted_extra);
      auto extra = accepted_extra;
      extra.insert(extra.end(), extras[best].begin(), extras[best].end());
      const BiasDesign after = Design(model_, pred, extra);
      const auto hb = HeldOutBias(before), ha = HeldOutBias(after);
      std::vector<double> sb, sa;
      for (int r : Scored()) {
        const auto x = ToScoreBlocks(hb[r], r), y = ToScoreBlocks(ha[r], r);
        sb.insert(sb.end(), x.begin(), x.end());
        sa.insert(sa.end(), y.begin(), y.end());
      }
      st.compensated_stability_ratio = sim::StdDev(sb) / std::max(sim::StdDev(sa), 1e-12);
      st.after = st.before;
      st.after.bias_rms_dph = ScoreBias(ha).rms();
      accepted_extra = extra;
      model_.effects.push_back(e);
    }
    dx.steps.push_back(st);
  }
  dx.extended = dx.steps.empty() ? dx.baseline : dx.steps.back().after;
  if (!dx.steps.empty() && has_bias_) {
    // Final bias RMS with every accepted bias regressor.
    const auto pred = SimulateAll(model_, all);
    dx.extended.bias_rms_dph = ScoreBias(HeldOutBias(Design(model_, pred, accepted_extra))).rms();
  }
  dx.extended_gyro = Build(nominal_, knobs_, model_);

  // Residual traces (fit-block resolution) for the report.
  const auto pb = SimulateAll(baseline_model, all), pe = SimulateAll(model_, all);
  const auto rb = ThermalResiduals(pb, all), re = ThermalResiduals(pe, all);
  std::vector<Eigen::VectorXd> bb, be;
  if (has_bias_) {
    bb = HeldOutBias(Design(baseline_model, pb, {}));
    be = HeldOutBias(Design(model_, pe, accepted_extra));
  }
  for (int r : all) {
    ResidualTrace tr;
    tr.run = runs_[r].run->id;
    tr.t_s = block_times_[r];
    auto block_means = [&](int col) {
      const Eigen::VectorXd m = BlockMeans(runs_[r].run->columns[col], r);
      return std::vector<double>(m.data(), m.data() + m.size());
    };
    auto negated = [](std::vector<double> v) {  // ThermalResiduals are simulated - measured
      for (double& x : v) x = -x;
      return v;
    };
    for (size_t s = 0; s < nominal_.sensors.size(); ++s) {
      if (runs_[r].sensor_col[s] < 0) continue;
      const std::string& ch = nominal_.sensors[s].channel;
      tr.measured[ch] = block_means(runs_[r].sensor_col[s]);
      tr.baseline[ch] = negated(rb[r][s]);
      tr.extended[ch] = negated(re[r][s]);
    }
    if (has_bias_ && bb[r].size() > 0) {
      tr.measured["bias_dph"] = block_means(runs_[r].bias_col);
      tr.baseline["bias_dph"] = std::vector<double>(bb[r].data(), bb[r].data() + bb[r].size());
      tr.extended["bias_dph"] = std::vector<double>(be[r].data(), be[r].data() + be[r].size());
    }
    dx.residuals.push_back(std::move(tr));
  }
  return dx;
}

}  // namespace

std::string CanonicalTarget(const GyroConfig& g, const std::string& effect, const std::string& target) {
  const sim::Effect* e = sim::FindEffect(effect);
  return e ? e->CanonicalTarget(g, target) : sim::CanonicalNodeTarget(g, target);
}

bool DiagnoseOptions::IsValid(std::string* error) const {
  std::string why;
  if (max_steps < 0) why = fmt::format("max_steps must be 0 or more (got {})", max_steps);
  else if (single_run_pieces < 2) why = fmt::format("single_run_pieces must be at least 2 (got {})", single_run_pieces);
  else if (!(fit_block_s > 0.0 && std::isfinite(fit_block_s)))
    why = fmt::format("fit_block_s must be a positive number of seconds (got {:g})", fit_block_s);
  else if (!(score_block_s >= fit_block_s && std::isfinite(score_block_s)))
    why = fmt::format("score_block_s must be at least fit_block_s = {:g} s (got {:g})", fit_block_s, score_block_s);
  else if (!(min_heldout_ratio >= 1.0) || !(min_heldout_ratio_thermal >= 1.0))
    why = fmt::format("min_heldout_ratio and min_heldout_ratio_thermal must be at least 1 (got {:g}, {:g})",
                      min_heldout_ratio, min_heldout_ratio_thermal);
  else if (!(min_score >= 0.0) || !(tie_score >= 0.0))
    why = fmt::format("min_score and tie_score must be 0 or more (got {:g}, {:g})", min_score, tie_score);
  else if (null_replicates < 0 || thermal_refits < 0)
    why = fmt::format("null_replicates and thermal_refits must be 0 or more (got {}, {})", null_replicates, thermal_refits);
  else
    calibration.IsValid(&why);
  if (error) *error = why;
  return why.empty();
}

Diagnosis Diagnose(const sim::Trace& data, const GyroConfig& nominal, const DiagnoseOptions& options) {
  std::string why;
  if (!options.IsValid(&why)) throw InputError("diagnose: " + why);
  Engine engine(data, nominal, options);
  return engine.Run();
}

CalibrationSummary Calibrate(const sim::Trace& data, const GyroConfig& nominal, const DiagnoseOptions& options) {
  std::string why;
  if (!options.IsValid(&why)) throw InputError("diagnose: " + why);
  const Engine engine(data, nominal, options);
  return engine.Calibrate().summary;
}

}  // namespace rlg::model
