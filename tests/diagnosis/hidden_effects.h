#pragma once
// Hidden-effect experiments for the diagnosis tests: simulate the diagnosis suite from the
// default gyro with one catalog effect switched on, at a strength drawn from a seeded
// generator, 3-6x the noise at 100 s averaging. This file is the truth side: the diagnosis
// code never sees it. The bodies are in hidden_effects.cpp and, for the GoogleTest checks,
// hidden_effects_checks.cpp, compiled once into rlg_test_support (tests/CMakeLists.txt).

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <map>
#include <optional>
#include <ostream>
#include <string>
#include <utility>
#include <vector>

#include "diagnosis/diagnose.h"
#include "diagnosis/statistics/rank.h"
#include "io/scenario_file.h"
#include "sim/noise.h"
#include "sim/scenario.h"
#include "sim/simulator.h"

namespace rlg::test {

struct HiddenCase {
  std::string effect;  ///< "none" for no effect
  std::string target;
  std::map<std::string, double> parameters;
  std::string checked;  ///< the parameter the test compares
  /// Effect RMS / noise RMS at 100 s: for thermal effects, of the part a calibration of the
  /// nominal gyro cannot take up (CalibrationProjector); raw_strength is the effect's own.
  double strength = 0.0;
  double raw_strength = 0.0;
};

/// Effect, targets to draw from, starting parameters (their direction) and the parameter to
/// check. Targets are those the data can identify (see README "What diagnosis can tell apart").
struct CatalogEntry {
  std::string effect;
  std::vector<std::string> targets;
  std::map<std::string, double> start;
  std::string checked;
  std::string scaled;  ///< the parameter scaled to reach the strength
};

/// The catalog the blind tests draw their hidden effects from, one entry per effect.
const std::vector<CatalogEntry>& HiddenCatalog();

/// scenarios/diagnosis-suite.toml: the suite the blind tests simulate.
sim::Scenario DiagnosisScenario();

/// The nominal gyro as diagnose gets it: the simulator's own gyro is the truth here, so its
/// parameters are known far better than a build tolerance.
sim::GyroConfig NominalForDiagnosis();

/// The gyro with every noise source off.
sim::GyroConfig Noiseless(sim::GyroConfig g);

/// A scenario with every noise off: the truth side's reference runs.
sim::Scenario Noiseless(sim::Scenario sc);

/// Noise RMS at 100 s of the default gyro: gyro (ARW and the flicker floor) or sensor (white
/// noise and resolution), from its own parameters.
double NoiseRms100(const sim::GyroConfig& g, bool bias);

/// 100 s means of a 1 s column (whole blocks only).
std::vector<double> Means100(const std::vector<double>& x);

/// Temperature-channel 100 s means of every run, channel by channel: one vector per channel.
std::vector<std::vector<double>> ChannelMeans100(const sim::Trace& t);

/// The part of a thermal effect that a calibration of the nominal gyro cannot take up, as the
/// largest channel RMS of 100 s means. A 5e-5 W/K link from the cathode to ambient moves T4
/// by 2 mK, but so does a 0.02 % change of the cathode's 0.4 W/K seal; no data can tell those
/// apart while the seal is known to 0.5 %. Linearised: the effect's 100 s means e less their
/// best fit J x by every knob the calibration has (log heat capacities, conductances,
/// radiation, source gains), each with the gyro's prior sd:
///   min |e - J x|^2 / s^2 + |x|^2 / prior^2,   s = sensor noise of a 100 s mean.
/// Truth side only: the test harness's own knob list, written from the gyro's parts.
class CalibrationProjector {
 public:
  explicit CalibrationProjector(const sim::Scenario& clean);

  /// Effect RMS before (raw) and after the calibration takes up what it can, largest channel.
  std::pair<double, double> Rms(const sim::EffectSpec& effect, double noise100, double prior_sd) const;

 private:
  Eigen::VectorXd Flat(const std::vector<std::vector<double>>& c) const;
  double LargestChannelRms(const Eigen::VectorXd& v) const;

  sim::Scenario clean_;
  std::vector<std::vector<double>> base_;
  Eigen::MatrixXd J_;
};

/// The channel of a sensor reading `node` without lag: the truth side's node temperatures.
std::string NodeChannel(const sim::GyroConfig& g, int node);

/// A bias regressor as a 1 s column of a noise-free run of the nominal gyro.
using Regressor = std::function<std::vector<double>(const sim::Run&)>;

/// Covariance ((°/h)²) of n consecutive means over blocks of L seconds of a gyro's bias noise
/// as the simulator makes it (sim::GyroNoise): ARW (white) plus the bias instability's
/// Gauss-Markov terms, of variance s² and correlation time T, whose block means covary by
///   s² (2T/L) (1 - (T/L)(1 - a))   at lag 0,   s² (T/L)² (1 - a)² a^(m-1)   at lag m >= 1,
/// a = exp(-L/T). The flicker floor is not white: its terms of 1e3-1e5 s put far more power
/// into a run's slow wander than the 100 s variance says.
Eigen::MatrixXd BlockMeanNoiseCovariance(const sim::GyroNoiseParams& p, double L, Eigen::Index n);

/// Least-squares projection of a bias effect (the noise-free runs `with` less `without`) on
/// the nominal bias model's free coefficients, which a calibration refits freely: a per-run
/// offset, b1 and b2 on the bias node, and per Langmuir gradient k and k c_T; plus `extra`
/// regressors when given. All on 100 s means; regressors from `without`, whose sensors read
/// the nodes.
struct BiasProjection {
  double raw = 0.0;   ///< RMS of the effect's 100 s means
  double left = 0.0;  ///< RMS of what the regressors cannot take up
  int blocks = 0;     ///< 100 s means in the record
  std::vector<double> extra_coefficients;
  /// Given `noise`: min over the coefficients of r' S^-1 r, r the 100 s means of the effect
  /// less the regressors' fit, S their covariance under that noise (BlockMeanNoiseCovariance,
  /// run by run): the noncentrality of the best test between the effect and the regressors.
  double noncentrality = 0.0;
};

BiasProjection ProjectBias(const sim::Trace& without, const sim::Trace& with, const sim::GyroConfig& g,
                           const std::vector<Regressor>& extra = {},
                           const sim::GyroNoiseParams* noise = nullptr);

/// Draws a case for `effect` from `seed` and returns the simulated data.
sim::Trace MakeHiddenCase(const std::string& effect, uint64_t seed, HiddenCase* truth);

/// Targets the data cannot tell apart count as the same (README, "What diagnosis can tell
/// apart"): a gradient is known up to the Langmuir gradients already in the bias model, and a
/// power drift acts on a heat source whichever of its nodes drives it.
bool SameTarget(const sim::GyroConfig& g, const std::string& effect, const std::string& a, const std::string& b);

/// A rate term on a node is exactly a gradient when the node's links other than the Langmuir
/// gradients already in the bias model reduce to one, not to ambient: then
/// C dT_n/dt = G (T_m - T_n) + (terms in the model) + P, and with constant P (a per-run
/// offset) k dT_n/dt [per min] = 60 k G / C (T_m - T_n). Returns that pair "n-m" and the
/// factor 60 G / C, or an empty pair when the node's rate is a hypothesis of its own.
std::pair<std::string, double> RateAsGradient(const sim::GyroConfig& g, const std::string& rate_target);

/// A bias candidate's regressor as diagnose builds it (in the answer's units and orientation),
/// or nullptr for a cause without one here (mode hops, thermal effects).
Regressor CandidateRegressor(const sim::GyroConfig& g, const std::string& cause, const std::string& target);

/// An answer whose difference from the truth has a noncentrality below this over the whole
/// record cannot be told from the truth by any method: two one-parameter answers are ranked
/// wrongly with probability Phi(-sqrt(lambda) / 2), 7 % at lambda = 9 (a 3 sigma separation),
/// more than the 5 % the confusion-matrix test allows. The detectability floor (3x the
/// noise RMS at 100 s) is the same 3 sigma per 100 s mean instead of over the record.
/// That bound holds for the noncentrality under the data's own noise (BiasProjection::
/// noncentrality), not for a sum of squares over the 100 s noise RMS: that one treats the
/// flicker floor as white and overstated the separation of slow differences 2-4x (a rate of
/// T1 against a block-cabinet gradient, hysteresis of the block against the cathode's: 11-30
/// as if white, 4.6-8.6 under the gyro's noise, where the best test errs 7-14 % of the time).
constexpr double kSeparableLambda = 9.0;

/// Whether a named answer is right, and the value its parameter should have.
struct Verdict {
  bool right = false;
  std::string why;       ///< "exact", "indistinguishable (lambda = ..)" or why not
  std::string key;       ///< the answer's parameter to compare
  double expected = 0.0;
};

/// Judges an answer against the truth. Right: the same cause on a target the data cannot
/// tell apart exactly (SameTarget); or, for bias effects, an answer whose regressor together
/// with the baseline's free coefficients takes up the truth's noise-free signal to a
/// noncentrality lambda below kSeparableLambda, weighed by the covariance of the 100 s means
/// of the gyro's noise (BiasProjection::noncentrality). For
/// bias answers the parameter to compare is the least-squares coefficient of that fit: the
/// truth's own for its own name, 60 G / C k_rate for a rate's exact twin (RateAsGradient).
Verdict Judge(const sim::GyroConfig& g, const HiddenCase& truth, const std::string& cause, const std::string& target);

/// The first search's best candidates, for failure messages.
std::string TopCandidates(const diagnosis::Diagnosis& d, size_t n = 4);

/// A clearly visible hidden effect and the parameter to compare.
struct ClearCase {
  std::string effect, target, checked;
  std::map<std::string, double> parameters;
};

/// gtest prints the case by name instead of its bytes.
void PrintTo(const ClearCase& c, std::ostream* os);

/// Each step's ties (DiagnosisStep::ties) within the band are the ones its "ambiguous:" note
/// lists, in its order and with its rounded score differences; those beyond it (stand-ins the
/// data preferred) the ones its "set aside:" note lists; a step without either has no such note.
void ExpectTiesAreTheAmbiguousNote(const diagnosis::Diagnosis& d);

/// Simulates the diagnosis suite with `c` on and diagnoses it against the nominal gyro:
/// the right cause and target, the parameter within 20 % (the catalog tests' bound), a held-out gain.
void ExpectClearEffectFound(const ClearCase& c);

/// An effect's name as a GoogleTest parameter name: dots become underscores.
std::string TestName(std::string effect);

}  // namespace rlg::test
