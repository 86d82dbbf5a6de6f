// The diagnosis engine's model and simulation, and stage 2 (calibration): see
// model/diagnosis_engine.h.

#include <ceres/ceres.h>
#include <ceres/normal_prior.h>

#include "diagnosis/engine.h"
#include "diagnosis/rank.h"
#include "diagnosis/screen.h"
#include "diagnosis/unexplained.h"
#include "sim/noise.h"
#include "sim/stats.h"

namespace rlg::diagnosis {

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
    // A source switched off (no power, or a gain of 0 in the file) has nothing to calibrate;
    // its log-gain would start at -infinity.
    if ((!net.sources[s].driven_by_data && net.sources[s].power_W <= 0.0) || !(net.sources[s].gain > 0.0)) continue;
    // The file's gain (1 unless a calibrated file, e.g. an extended-gyro.toml, sets it).
    k.push_back({"gain:" + net.sources[s].name, net.sources[s].gain, [s](GyroConfig& c, double v) {
                   c.network.sources[s].gain = v;
                 }});
  }
  return k;
}

GyroConfig Build(const GyroConfig& nominal, const std::vector<BaseKnob>& knobs, const Model& m) {
  GyroConfig g = nominal;
  for (size_t i = 0; i < knobs.size(); ++i) knobs[i].set(g, m.base[i]);
  for (const auto& e : m.effects) sim::ApplyEffect(e, g);
  return g;
}

BlockTimes TimesOf(const std::vector<double>& t, std::pair<size_t, size_t> b) {
  BlockTimes out{0.0, 0.0};
  for (size_t i = b.first; i < b.second; ++i) out.mean += t[i];
  out.mean /= static_cast<double>(b.second - b.first);
  for (size_t i = b.first; i < b.second; ++i) out.variance += (t[i] - out.mean) * (t[i] - out.mean);
  out.variance /= static_cast<double>(b.second - b.first);
  return out;
}

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

Prediction Simulate(const GyroConfig& g, const PreparedRun& p, const std::vector<BlockTimes>& blocks, double ambient_C,
                    double start_offset_C, int n_nodes, const sim::SolverOptions& solver) {
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
  // Powered on after a soak: every state starts at the ambient of the first sample (and the
  // run's start offset, Model::start), which is integrated from there through each block's
  // mean sample time.
  std::vector<double> t = {p.run->t_s.front()};
  for (const auto& b : blocks) t.push_back(b.mean);
  const Eigen::VectorXd x0 = Eigen::VectorXd::Constant(net.num_states(), ambient.Value(p.run->t_s.front()) + start_offset_C);
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

Engine::Engine(const sim::Trace& data, const GyroConfig& nominal, const DiagnoseOptions& o)
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
    // One run: held out in time (docs/diagnosis.md). It is cut into equal pieces; the model is
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
  model_.start.assign(runs_.size(), 0.0);
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
    // Never beyond the score-block noise itself: where a record's nonzero second differences
    // are mostly its corners (60 s samples of an exact ramp), PointNoise measures them. A
    // noisy record is smoothed instead (diagnosis::LoggedAmbientCurve), and a step between
    // two samples is a step at the second (diagnosis::InputJumps).
    const int amb = runs_[r].run->Find("T_amb");
    ambient_noise_.push_back(0.0);
    start_sd_.push_back(0.0);
    if (amb >= 0) {
      runs_[r].ambient =
          diagnosis::LoggedAmbient(t, runs_[r].run->columns[amb], runs_[r].sample_period_s, noise_, &start_sd_.back());
      if (runs_[r].ambient_known) {
        std::vector<std::pair<double, double>> pts;
        for (size_t k = 0; k < t.size(); ++k) pts.emplace_back(t[k], runs_[r].run->columns[amb][k]);
        ambient_noise_.back() = diagnosis::NoiseAtEveryPoint(pts);
      }
    }
  }
  RequireScoreBlocks();
  const double white = 60.0 * nominal.noise.arw_deg_per_sqrt_h / std::sqrt(runs_.front().fit_block_s);
  // A noise-free gyro file still needs a scale for its prior: 1e-6 °/h, far below any
  // gyro's noise, keeps the prior from deciding anything the data can.
  bias_block_noise_ = std::max(std::hypot(white, 0.664 * nominal.noise.bias_instability_dph), 1e-6);
}

bool Engine::KnobsInConflict(const Model& m) const {
  CalibrationSummary c;
  for (size_t i = 0; i < knobs_.size(); ++i)
    c.knobs.push_back({knobs_[i].name, knobs_[i].nominal, m.base[i], KnobShiftSigma(m, i)});
  return !c.PriorConflicts().empty();
}

Engine::FitSummary Engine::FitThermal(Model& m, const std::vector<Free>& free, const std::vector<int>& which,
                                      const std::vector<double>& channel_var, int max_iterations,
                                      Eigen::MatrixXd* jtj_out) const {
  if (free.empty()) return {};
  // Parameter blocks: the shared parameters (knobs, effect parameters) and, per run, its own
  // nuisances (ambient, heater gains). A run's residuals depend on the shared block and its
  // own only, so each run is one residual block: a numeric Jacobian re-simulates one run per
  // parameter instead of every run.
  std::vector<size_t> shared;
  std::map<int, std::vector<size_t>> own;  // run -> indices into free
  for (size_t i = 0; i < free.size(); ++i) {
    const bool per_run = free[i].kind == Free::kAmbient || free[i].kind == Free::kRunGain || free[i].kind == Free::kStart;
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
  Calibration out = CalibrateFrom(model_);
  if (!KnobsInConflict(out.model)) return out;
  // A conflict is evidence of missing structure, or, where the fit also misses the data by
  // well over their noise, of a local minimum. Only then: a missing mass at 4x the noise
  // bent the knobs into conflict with a fit at the noise (residual variance 1.1x the white
  // noise's), and a restart took more of the mass into the capacities than the search could
  // then find; the heavy nominal's wrong minima missed by ~4x in variance.
  bool misses = false;
  for (size_t s = 0; s < nominal_.sensors.size(); ++s) {
    double white = 0.0;
    int runs = 0;
    for (int r : fit_) {
      if (runs_[r].sensor_col[s] < 0 || thermal_blocks_[r].empty()) continue;
      const auto [from, to] = thermal_blocks_[r].front();
      white += std::pow(WhiteNoiseSd(runs_[r].run->columns[static_cast<size_t>(runs_[r].sensor_col[s])]), 2) /
               static_cast<double>(to - from);
      ++runs;
    }
    // Twice the white noise's variance of a fit block, or of the variances' floor.
    if (runs > 0) misses = misses || out.channel_var[s] > 2.0 * std::max(white / runs, 2.5e-7);
  }
  if (!misses) return out;
  // The heat capacities' common scale (every time constant at once, which a nominal can miss by more than its
  // prior says) is searched on a grid of factors 0.5-2 by the unweighted chi² of the fit runs,
  // and the fit repeated from the best. The likelier of the two calibrations is kept.
  const std::vector<double> unit(nominal_.sensors.size(), kUnitChannelVar);
  double best_f = 1.0, best_chi2 = std::numeric_limits<double>::infinity();
  for (int i = -6; i <= 6; ++i) {
    const double f = std::pow(2.0, i / 6.0);
    Model trial = model_;
    for (size_t q = 0; q < knobs_.size(); ++q)
      if (knobs_[q].name.rfind("C:", 0) == 0) trial.base[q] *= f;
    try {
      const double chi2 = ThermalChi2(ThermalResiduals(SimulateAll(trial, fit_), fit_), fit_, unit);
      if (chi2 < best_chi2) best_chi2 = chi2, best_f = f;
    } catch (const std::exception&) {  // a factor the simulation cannot run is no start
    }
  }
  if (best_f == 1.0) return out;
  Model start = model_;
  for (size_t q = 0; q < knobs_.size(); ++q)
    if (knobs_[q].name.rfind("C:", 0) == 0) start.base[q] *= best_f;
  try {
    Calibration again = CalibrateFrom(start);
    if (CalibrationDeviance(again) < CalibrationDeviance(out)) {
      again.summary.start_capacity_scale = best_f;
      return again;
    }
  } catch (const NumericalError&) {  // the nominal's fit stands
  }
  return out;
}

double Engine::CalibrationDeviance(const Calibration& c) const {
  const auto res = ThermalResiduals(SimulateAll(c.model, fit_), fit_);
  double d = ThermalChi2(res, fit_, c.channel_var) + KnobPriorCost(c.model);
  for (size_t s = 0; s < nominal_.sensors.size(); ++s) {
    size_t n = 0;
    for (int r : fit_) n += res[r][s].size();
    d += static_cast<double>(n) * std::log(c.channel_var[s]);
  }
  return d;
}

Engine::Calibration Engine::CalibrateFrom(const Model& start) const {
  // Channel variances come from a first pass (unit weights), then the fit is repeated with
  // them; the held-out runs' nuisances follow with the knobs fixed.
  const CalibrationOptions& co = o_.calibration;
  Calibration out;
  out.model = start;
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
    s.knobs.push_back({knobs_[i].name, nominal, calibrated, KnobShiftSigma(out.model, i),
                       std::sqrt(std::max(0.0, s.covariance(ii, ii)))});
  }
  for (int r : all)
    if (runs_[r].nuisance == r && runs_[r].ambient_known && start_sd_[r] > 0.0)
      s.starts.push_back({runs_[r].label, out.model.start[r], start_sd_[r]});
  return out;
}

}  // namespace rlg::diagnosis
