#pragma once
/// One optional effect of the catalog (scenarios/README.md, Effects) as an object: what the simulator
/// switches on and what `diagnose` can name as a cause. In the manner of Ceres' LossFunction
/// family, each effect is a small class in sim/effects/ with its formula and units written
/// above it, and one table (sim/effect_registry.h) lists them in catalog order.
///
/// An effect knows
///  - its name and what it acts on (EffectKind), and which targets it can act on in a gyro
///    (Targets: nodes, node pairs, pairs with ambient, or sensor channels);
///  - its parameters (EffectParameter): unit, sign, a physically plausible range with its
///    source, what a gyro file may give, a default, and a start value;
///  - how it changes a GyroConfig (Apply: network elements, sensor properties or bias terms);
///  - for bias effects, its term as the diagnosis's regressor (Regressors): the term at unit
///    coefficient, computed by the same static function (`Bias_dph`) the simulator's
///    BiasModel calls.
/// Effects are stateless and const; the registry owns one of each.

#include <Eigen/Core>
#include <functional>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "sim/gyro.h"

namespace rlg::sim {

/// What an effect acts on.
enum class EffectKind {
  kThermal,  ///< the thermal network (nodes, links, radiation, sources)
  kSensor,   ///< one temperature channel's reading
  kBias,     ///< the gyro's bias, through an extra term
};

/// Parameter values by name, as in an [[effects]] table.
using ParameterMap = std::map<std::string, double>;

/// One parameter of an effect.
struct EffectParameter {
  /// How `diagnose` treats the parameter when it fits the effect.
  enum class Fit {
    kSize,   ///< fitted; the screening step scales it (the effect's strength)
    kShape,  ///< fitted from its start, not scaled by the screening step (a missing mass's
             ///< capacity, which trades against its conductance)
    kFixed,  ///< held at its start and left out of the report (a drift's reference temperature)
  };

  std::string name;  ///< key in an [[effects]] table, unit in the name: "conductance_W_per_K"
  std::string unit;  ///< for reading: "W/K"
  bool positive = false;  ///< > 0 always (fitted in log units); false: either sign
  /// Physically plausible range: a fitted value outside it is suspect. lo < hi.
  double lo = 0.0, hi = 0.0;
  /// Why that range: "[src] ..." from a published source (docs/physics.md, the paper) or
  /// "[est] ..." with the reasoning.
  std::string source;
  /// What a gyro or scenario file may give (far wider than `lo`, `hi`: a value beyond is a
  /// mistake, sim/limits.h); ReadEffect refuses anything outside with file and line.
  double file_lo = 0.0, file_hi = 0.0;
  /// Value when a file omits the parameter; nullopt: required.
  std::optional<double> default_value;
  /// Inside [lo, hi]: where `diagnose`'s screening simulation starts (thermal and sensor
  /// effects: small enough to be linear, large enough to be far above round-off in the
  /// simulated temperatures); for bias effects, which are fitted linearly, a typical size.
  double start = 0.0;
  Fit fit = Fit::kSize;
  /// > 0: `diagnose` holds a kShape parameter with a log-normal prior of this factor (1 sd)
  /// around `start`; 0: no prior.
  double prior_factor = 0.0;
};

/// A parameter value outside its effect's physically plausible range (EffectParameter::lo, hi).
struct RangeViolation {
  const EffectParameter* parameter = nullptr;  ///< name, unit, range and its source
  double value = 0.0;
};

/// Where an effect's candidate targets are drawn from.
struct TargetSpace {
  /// The model as it stands: its links, sources, sensors and bias terms decide what is new.
  const GyroConfig& gyro;
  /// Only the first `nodes` nodes are candidates: nodes an effect added (a missing mass) are
  /// not the nominal gyro's.
  int nodes = 0;
  /// Sensor channels with data, sorted.
  std::vector<std::string> channels;
};

/// Node temperatures (°C) and rates (°C/s) of one run, nodes x samples (fit-block means in
/// `diagnose`).
struct NodeTrack {
  const Eigen::MatrixXd& T;
  const Eigen::MatrixXd& Tdot;
};

/// A bias effect on one target as a regressor of `diagnose`'s linear bias fit.
struct BiasRegressor {
  std::string target;
  /// The effect's term at unit coefficient at sample k of run `run`. Terms without history
  /// (a rate, a gradient) read `track`; terms with history (hysteresis, mode hops) were
  /// computed once, from the tracks Effect::Regressors was given.
  std::function<double(const NodeTrack& track, size_t k, int run)> column;
  /// The parameters `diagnose` reports for a fitted coefficient of the column.
  std::function<ParameterMap(double coefficient)> parameters;
  /// Parameters of the column's shape searched on the data (a mode hop's spacing, range and
  /// centre): `diagnose` counts them with the coefficient in its information criterion.
  int searched_parameters = 0;
};

/// How much a candidate column (per run, one value per sample of the tracks the regressors
/// were given) explains of what the model leaves: `diagnose` gives the drop of the residual sum
/// of squares of its in-sample bias fit when the column is added (larger is better, >= 0).
using ColumnGain = std::function<double(const std::vector<std::vector<double>>& column)>;

class Effect {
 public:
  virtual ~Effect() = default;
  Effect(const Effect&) = delete;
  Effect& operator=(const Effect&) = delete;

  const std::string& name() const { return name_; }
  EffectKind kind() const { return kind_; }
  /// In the order a file lists them (scenarios/README.md).
  const std::vector<EffectParameter>& parameters() const { return parameters_; }
  /// The parameter `name`, or nullptr.
  const EffectParameter* FindParameter(const std::string& name) const;
  /// Every parameter at its start value.
  ParameterMap Start() const;
  /// True when the effect's size (its kSize parameters) may take either sign.
  bool SizeIsSigned() const;
  /// `p` without the kFixed parameters: what a report shows.
  ParameterMap Reported(ParameterMap p) const;

  /// Targets the effect can act on in `space`, in a fixed order: what `diagnose` tries.
  virtual std::vector<std::string> Targets(const TargetSpace& space) const = 0;
  /// Network elements Apply appends at the end of the gyro's lists (what a gyro without its
  /// effects lacks: io/gyro_toml.h writes that gyro plus [[effects]]).
  struct Appended {
    size_t nodes = 0, links = 0, radiation = 0;
  };
  virtual Appended AppendsToNetwork() const { return {}; }
  /// Changes `gyro`. `p` holds every parameter of parameters() (given or default; ApplyEffect
  /// checks that). InputError (plain message) for a target or value the effect cannot take.
  virtual void Apply(const std::string& target, const ParameterMap& p, GyroConfig& gyro) const = 0;
  /// Canonical form of a target for comparisons: a sensor effect's channel as it is, any other
  /// target as CanonicalNodeTarget gives it.
  std::string CanonicalTarget(const GyroConfig& gyro, const std::string& target) const;

  /// Bias effects: a regressor per target of `space`, from the node tracks of every run. An
  /// effect whose term has a shape beyond its linear coefficient (a mode hop's spacing, centre
  /// and range) searches it by `gain` and returns its best. Empty for thermal and sensor effects.
  virtual std::vector<BiasRegressor> Regressors(const TargetSpace& space,
                                                const std::vector<const Eigen::MatrixXd*>& T_runs,
                                                const ColumnGain& gain) const;
  /// Bias effects whose term is a function of temperature tracks alone, no parameter of the
  /// gyro file's bias physics (a rate, a gradient, hysteresis; not a mode hop, which needs the
  /// cavity's length and expansion): what `diagnose` tries on measured channels when it has no
  /// thermal network (diagnosis/measured_candidates.h). False for every other effect.
  virtual bool ComputedFromTracks() const { return false; }
  /// The parameters to apply for those a fit reports: the same, except where only a
  /// combination is identifiable (hysteresis).
  virtual ParameterMap FromReported(const ParameterMap& reported) const { return reported; }
  /// The parameters of a fit's report (mapped by FromReported to what Apply takes) that lie
  /// outside their plausible range, in parameter order; kFixed ones are not checked. Empty:
  /// the effect is plausible at this size. Not empty: the fit put it at a size no such cause
  /// has: a direction the data leave unbounded, or the cause stands in for something else.
  std::vector<RangeViolation> OutsidePlausibleRange(const ParameterMap& reported) const;
  /// |reported main parameter| over its typical size [est], to rank candidates that explain
  /// the data equally well; 1 for effects without one.
  virtual double Implausibility(const ParameterMap& reported) const;
  /// What experiment separates this effect from the others within a tie (causes of the tied
  /// candidates, this one among them); empty when the general advice for its kind applies.
  virtual std::string SeparationAdvice(const std::set<std::string>& tied_causes, bool ambient_logged) const;

 protected:
  Effect(std::string name, EffectKind kind, std::vector<EffectParameter> parameters);
  /// Index of the sensor reading `channel`; InputError naming this effect otherwise.
  int RequireSensor(const GyroConfig& gyro, const std::string& channel) const;
  /// |reported[key]| / typical, or 1 when the fit reported no `key`.
  static double Relative(const ParameterMap& reported, const std::string& key, double typical);

 private:
  std::string name_;
  EffectKind kind_;
  std::vector<EffectParameter> parameters_;
};

/// A conductance between two nodes or a node and ambient (W/K), with `start`: the parameter
/// thermal.missing_mass and thermal.missing_link share.
EffectParameter ConductanceParameter(double start);

/// A node by name, or the node a channel's sensor sits on; kAmbient for "ambient" when
/// allowed. InputError otherwise.
int ResolveNode(const GyroConfig& gyro, const std::string& name, bool allow_ambient);
/// Two different nodes "a-b" (ResolveNode each; only the second may be ambient).
std::pair<int, int> ResolvePair(const GyroConfig& gyro, const std::string& target, bool allow_ambient);
/// "a-b" for every pair of the first `nodes` nodes (a before b in node order), each node's
/// pairs followed by "a-ambient" when `with_ambient`.
std::vector<std::string> NodePairs(const GyroConfig& gyro, int nodes, bool with_ambient);
/// A node target with channels replaced by their sensors' nodes; a pair "a-b" also in name
/// order, unless its second end is ambient.
std::string CanonicalNodeTarget(const GyroConfig& gyro, const std::string& target);
/// How `diagnose` names a node: the channel of a sensor reading it without lag, else its name.
std::string NodeTarget(const GyroConfig& gyro, int node);

}  // namespace rlg::sim
