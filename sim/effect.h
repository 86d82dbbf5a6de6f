#pragma once
/// One optional effect of the catalog (scenarios/README.md, Effects) as an object: the physics the
/// simulator switches on. In the manner of Ceres' LossFunction family, each effect is a small
/// class in sim/effects/ with its formula and units written above it, and one table
/// (sim/effect_registry.h) lists them in catalog order.
///
/// An effect knows
///  - its name and what it acts on (EffectKind);
///  - its parameters (EffectParameter): unit, sign, a physically plausible range with its
///    source, what a gyro file may give, and a default;
///  - how it changes a GyroConfig (Apply: network elements, sensor properties or bias terms);
///  - for bias effects, its term (a static `Bias_dph` the simulator's BiasModel calls).
/// How `diagnose` searches, fits and explains an effect (its candidate targets, start values,
/// regressors, ranking and advice) is the diagnosis's own: diagnosis/catalog/effect_search.h.
/// Effects are stateless and const; the registry owns one of each.

#include <map>
#include <optional>
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
  /// A convention of the form, not a property of the gyro (a drift's reference temperature):
  /// no population spreads it, no fit moves it, no report shows it, no range is checked.
  bool reference = false;
};

/// A parameter value outside its effect's physically plausible range (EffectParameter::lo, hi).
struct RangeViolation {
  const EffectParameter* parameter = nullptr;  ///< name, unit, range and its source
  double value = 0.0;
};

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

  /// The parameters of `applied` (what Apply takes) that lie outside their plausible range, in
  /// parameter order; reference parameters are not checked. Empty: plausible at this size.
  std::vector<RangeViolation> OutsidePlausibleRange(const ParameterMap& applied) const;

 protected:
  Effect(std::string name, EffectKind kind, std::vector<EffectParameter> parameters);
  /// Index of the sensor reading `channel`; InputError naming this effect otherwise.
  int RequireSensor(const GyroConfig& gyro, const std::string& channel) const;

 private:
  std::string name_;
  EffectKind kind_;
  std::vector<EffectParameter> parameters_;
};

/// A conductance between two nodes or a node and ambient (W/K): the parameter
/// thermal.missing_mass and thermal.missing_link share.
EffectParameter ConductanceParameter();

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
