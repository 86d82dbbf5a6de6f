#pragma once
/// The diagnosis engine (internal to rlg_model; model/diagnose.h is the interface): the prepared
/// data of one diagnosis, the model under test (nominal gyro + calibrated knobs + effects +
/// per-run nuisances), its noise-free simulation on fit blocks, and the stages that need both:
/// calibration (diagnosis_engine.cpp), the thermal search (diagnosis_thermal.cpp), the bias
/// search and null bootstrap (diagnosis_bias.cpp) and the run of all stages (diagnose.cpp). The
/// pure stages are in their own headers (diagnosis_*.h). Nothing is shared between stages but
/// their arguments and results: the searches are const; Run() owns the current model.

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <fmt/format.h>
#include <fmt/ranges.h>
#include <functional>
#include <limits>
#include <map>
#include <numeric>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "diagnosis/diagnose.h"
#include "diagnosis/bias_fit.h"
#include "diagnosis/prepare.h"
#include "diagnosis/score.h"
#include "sim/effect_registry.h"
#include "sim/errors.h"
#include "sim/simulator.h"

namespace rlg::diagnosis {

using sim::GyroConfig;
using sim::Profile;

// ---------------------------------------------------------------------------------------------
// Model: nominal gyro + baseline knobs + effects (+ per-run ambient when unknown)

struct BaseKnob {
  std::string name;
  double nominal;
  std::function<void(GyroConfig&, double)> set;
};

std::vector<BaseKnob> BaselineKnobs(const GyroConfig& g);

struct Model {
  std::vector<double> base;              ///< baseline knob values
  std::vector<sim::EffectSpec> effects;  ///< accepted (and candidate) effects with parameters
  std::vector<double> ambient;           ///< per run, used where the ambient is unknown
  /// Per run, where the ambient is logged with noise: every state's start minus the ambient
  /// curve's value at the first sample (°C). The gyro starts soaked at the true ambient, which
  /// the curve knows only to its first value's standard error (its prior, Engine::AmbientFree);
  /// at 1 s samples the reference generator's curves started 0.4-0.8 mK off, which the block
  /// and anode kept for hours. Like per-run gains, its prior counts in the calibration's fit
  /// and in every refit, not in a candidate's score (KnobPriorCost: the knobs' alone).
  std::vector<double> start;
  std::vector<std::vector<double>> run_gain;  ///< per run and data-driven source (per_run_source_gains)
};

GyroConfig Build(const GyroConfig& nominal, const std::vector<BaseKnob>& knobs, const Model& m);

struct Prediction {
  std::vector<std::vector<double>> sensor;  ///< per gyro sensor, per fit block
  Eigen::MatrixXd T, Tdot;                  ///< nodes x fit blocks (original nodes only)
};

/// The sample times of one fit block: their mean and their variance about it.
struct BlockTimes {
  double mean, variance;
};

BlockTimes TimesOf(const std::vector<double>& t, std::pair<size_t, size_t> b);

/// Block means of smooth quantities (rows of q, one column per block) from their values at
/// the blocks' mean sample times: the mean over a block's samples is q(m) + q''(m) var(t) / 2
/// to fourth order, with q'' / 2 the second divided difference through this block's and its
/// neighbours' values (the nearest three at a run's ends). Taking q(m) alone was wrong by
/// q'' var / 2 where an ambient corner starts a curvature: 0.22 mK on the cabinet after a
/// ramp's start (10 s blocks of 0.1 s or 1 s data), 1.7 times the noise of a 100 s mean of
/// 0.1 s data. One-sample blocks have no variance and stay as they are.
void ToBlockMeans(const std::vector<BlockTimes>& blocks, Eigen::Ref<Eigen::MatrixXd> q);

/// Noise-free simulation of the block means of a run's fit blocks (ToBlockMeans of each
/// output at the blocks' mean sample times).
Prediction Simulate(const GyroConfig& g, const PreparedRun& p, const std::vector<BlockTimes>& blocks, double ambient_C,
                    double start_offset_C, int n_nodes, const sim::SolverOptions& solver);

// ---------------------------------------------------------------------------------------------
// The diagnosis engine

/// A free parameter of an optimisation: a baseline knob, an effect parameter, or a run's
/// nuisance (its ambient, a source's gain, its start).
struct Free {
  enum Kind { kBase, kEffect, kAmbient, kRunGain, kStart } kind;
  int index;
  std::string param;  ///< effect parameter name
  bool log;
  double prior_center = 0.0;  ///< internal units
  double prior_sigma = 0.0;   ///< 0 = none
};

class Engine {
 public:
  /// Prepares `data` for `nominal` (stage 1): runs, the held-out split, fit blocks, a logged
  /// ambient as a simplified polyline, noise levels. InputError as Diagnose.
  /// Keeps references to `data` and `nominal`: both must outlive the engine.
  Engine(const sim::Trace& data, const GyroConfig& nominal, const DiagnoseOptions& o);

  Diagnosis Run();

  /// Stage 3: the calibrated baseline model, the channel variances it weighs residuals with,
  /// and its summary.
  struct Calibration {
    Model model;
    std::vector<double> channel_var;
    CalibrationSummary summary;
  };
  Calibration Calibrate() const;
  /// Calibrate's passes from the model `start` (the knobs of the first pass's start).
  Calibration CalibrateFrom(const Model& start) const;
  /// -2 ln L of a calibration on the fit runs up to a constant: sum over channels of n ln
  /// var (its residuals' own variance) + the weighted chi² + the knobs' prior. Two fits with
  /// different channel variances compare by it, not by their costs.
  double CalibrationDeviance(const Calibration& c) const;

  /// Stage 4 on a calibration, as Run's first search makes it: every thermal and sensor
  /// candidate (screened, the best thermal_refits refitted and scored), best screening gain
  /// first.
  std::vector<Candidate> FirstThermalCandidates(const Calibration& cal) const;
  /// Stage 4, bias: every bias candidate on a calibration (empty without bias data), in
  /// catalog order.
  std::vector<Candidate> FirstBiasCandidates(const Calibration& cal) const;

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
    for (int r : which) out[r] = SimulateRun(g, m, runs_[r], r);
    return out;
  }
  /// Run r of gyro g (Build of m) as prepared in `p` (runs_[r], or a copy with another ambient
  /// curve), with m's nuisances for it: its ambient and, with per-run gains, its board's own
  /// heater gains.
  Prediction SimulateRun(const GyroConfig& g, const Model& m, const PreparedRun& p, int r) const {
    const int q = p.nuisance;
    const double start = m.start.empty() ? 0.0 : m.start[q];
    if (m.run_gain.empty()) return Simulate(g, p, block_spans_[r], m.ambient[q], start, n_nodes_, solver_);
    GyroConfig gr = g;  // this run's board: its own heater gains
    for (size_t s = 0; s < gr.network.sources.size(); ++s) gr.network.sources[s].gain *= m.run_gain[q][s];
    return Simulate(gr, p, block_spans_[r], m.ambient[q], start, n_nodes_, solver_);
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

  /// ScoreSsr over runs and channels (°C²): the held-out RMS of docs/diagnosis.md comes from it,
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
    if (f.kind == Free::kAmbient) m.ambient[f.index] = v - kKelvin;
    if (f.kind == Free::kRunGain) m.run_gain[f.index][std::stoul(f.param)] = v;
    if (f.kind == Free::kStart) m.start[f.index] = v - kKelvin - CurveStart(f.index);
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
      if (f.kind == Free::kAmbient) v = m.ambient[f.index] + kKelvin;
      if (f.kind == Free::kRunGain) v = m.run_gain[f.index][std::stoul(f.param)];
      if (f.kind == Free::kStart) v = CurveStart(f.index) + m.start[f.index] + kKelvin;
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
                        const std::vector<double>& channel_var, int max_iterations, Eigen::MatrixXd* jtj_out = nullptr) const;


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

  /// Run r's logged ambient curve at its first sample (°C). A start is fitted as this plus
  /// Model::start, an absolute temperature in kelvin (kKelvin), as an unlogged ambient is: the
  /// numeric Jacobian's relative step (1e-6) is then 3e-4 K at any chamber temperature, whereas
  /// 1e-6 of a 0.2 mK offset, 2e-10 °C, is below CVODE's tolerance and its derivative noise (a
  /// refit through CVODE then takes minutes, not seconds), and 1e-6 of a 0 °C chamber in °C is
  /// Ceres' floor of 1.5e-8.
  double CurveStart(int r) const { return runs_[r].ambient.Value(runs_[r].run->t_s.front()); }
  static constexpr double kKelvin = 273.15;  ///< a run's ambient and start are fitted in K

  /// Per-run nuisances: the ambient where it was not logged and, with per_run_source_gains,
  /// each data-driven source's gain (runs from different boards). Gains are relative to the
  /// global ones, so they get a prior of the gyro's relative uncertainty around 1. Where the
  /// ambient is logged with noise, the start (Model::start) with a prior of the standard error
  /// of the curve's first value (start_sd_).
  std::vector<Free> AmbientFree(const std::vector<int>& which) const {
    std::vector<Free> f;
    for (int r : which) {
      if (runs_[r].nuisance != r) continue;  // shares its run's, fitted with it
      if (!runs_[r].ambient_known) f.push_back({Free::kAmbient, r, "", false});
      if (runs_[r].ambient_known && start_sd_[r] > 0.0)
        f.push_back({Free::kStart, r, "", false, CurveStart(r) + kKelvin, start_sd_[r]});
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
  /// o_.progress with the step's prefix ("step 2: "), when set.
  void Progress(const std::string& what) const {
    if (o_.progress) o_.progress(step_prefix_ + what);
  }
  std::string step_prefix_;
  std::vector<PreparedRun> runs_;
  std::vector<BaseKnob> knobs_;
  double noise_;               // ScoreBlockNoise
  /// Per run, the logged ambient's noise at every point (NoiseAtEveryPoint of its samples, °C);
  /// 0 without a log or for an exact one.
  std::vector<double> ambient_noise_;
  /// Per run, the standard error of the logged ambient curve's value at the first sample (°C;
  /// LoggedAmbient), the prior of Model::start; 0 without a noisy log.
  std::vector<double> start_sd_;
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
  /// Moves a trial effect's (model.effects[e]) free parameters to the best start for its local
  /// refit: the current values or a point of a log-space grid over each positive parameter's
  /// plausible range (diagnosis_multistart.h), by chi² on the fit runs plus the parameters'
  /// priors, the baseline knobs held; or, given `chi2`, by chi2(trial) plus the priors (the
  /// knobs profiled out, ThermalCandidates).
  void SearchEffectStart(Model& trial, int e, const std::vector<Free>& effect_free,
                         const std::vector<double>& channel_var,
                         const std::function<double(const Model&)>& chi2 = nullptr) const;
  /// The scored thermal candidates of model m (chi2_base: its thermal chi² on the fit runs).
  /// A refitted candidate's score is the drop of chi² plus the knobs' prior (KnobPriorCost)
  /// less k ln n: a cause that lets the knobs return to their nominal is credited for it. When
  /// a knob of m is in conflict with its prior (KnobsInConflict), each refit is also started
  /// from the nominal knobs and the better end point (chi² + prior) is kept: a calibration that
  /// bent the knobs to imitate the missing structure is no start to find it from.
  /// *null (when given) gets the score a significant one must reach (NullThermalReplicates).
  std::vector<Candidate> ThermalCandidates(const Model& m, const std::vector<Prediction>& pred, double chi2_base,
                                           const std::vector<double>& channel_var, std::vector<Model>* models,
                                           NullBootstrap* null = nullptr) const;
  /// The parametric bootstrap of the thermal acceptance score (docs/diagnosis.md; the
  /// thermal twin of NullBiasThreshold): o_.null_replicates residual vectors (columns, in
  /// ThermalCandidates' flattened order, in channel-noise units) of what model m leaves on
  /// data it made itself. Each holds every channel's white noise (WhiteNoiseSd of the run's
  /// column, per fit block) and, for a noisy logged ambient, the error the curve through it
  /// carries: the ambient logged again as m's curve plus white noise of the column's own level
  /// (NoiseAtEveryPoint), smoothed as the data's was (LoggedAmbient), and m driven by both
  /// curves. That error is slow (a knot's value holds for a whole segment) and every node feels
  /// it, so white-noise scoring underrates it most: on refgen's nulls the residuals' power at
  /// 3000 s was 2-3x the white level, and thermal candidates took it up on 8 of 60 nulls.
  /// ThermalCandidates scores each replicate as it screens (the best candidate's screening
  /// gain less k ln n, as a refit is scored); the threshold is max(min_score, the largest).
  Eigen::MatrixXd NullThermalReplicates(const Model& m, const std::vector<Prediction>& pred,
                                        const std::vector<double>& channel_var) const;
  /// What the report says of a thermal null bootstrap.
  std::string ThermalNullNote(const NullBootstrap& null) const;
  /// sum over the baseline knobs of ((ln x - ln nominal) / s)², s the gyro file's relative
  /// uncertainty: the prior term the calibration minimises (twice its cost), on the chi² scale.
  double KnobPriorCost(const Model& m) const {
    double c = 0.0;
    for (size_t i = 0; i < knobs_.size(); ++i) c += std::pow(KnobShiftSigma(m, i), 2);
    return c;
  }
  /// Knob i of m shifted from its nominal, ln(value / nominal) in prior sds (KnobCalibration::
  /// shift_sigma).
  double KnobShiftSigma(const Model& m, size_t i) const {
    return std::log(m.base[i] / knobs_[i].nominal) / nominal_.calibration_uncertainty;
  }
  /// Some knob of m beyond kPriorConflictSigma prior sds of its nominal: a knob bent to imitate
  /// structure the network lacks. A joint conflict alone (CalibrationSummary::JointConflict:
  /// many knobs a little off together, a nominal off by more than it says) is reported, not
  /// restarted from: no cause returns a uniformly heavy nominal, and the restarts from its
  /// nominal knobs cost refgen's heavy nominal 550 s instead of 8 s on one seed (radiation
  /// refits through CVODE from far off).
  bool KnobsInConflict(const Model& m) const;
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

}  // namespace rlg::diagnosis
