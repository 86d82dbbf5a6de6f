#pragma once
/// How `diagnose` searches, fits and explains each effect of the catalog: one table keyed by the
/// effect (EffectSearches, in catalog order), beside the physics of sim/effect.h, which says what
/// an effect does to a gyro and nothing of how it is found. Per effect:
///  - its candidate targets in a model (Targets: nodes, node pairs, pairs with ambient, channels);
///  - per parameter, how a fit treats it and where it starts (ParameterSearch);
///  - for bias effects, its term as a regressor of the linear bias fit (Regressors): the term at
///    unit coefficient, by the same static `Bias_dph` the simulator's BiasModel calls, and a
///    shape searched on the data where the term has one (a mode hop: mode_hop_search.h);
///  - what a fit reports and how that maps back to the effect's parameters (FromReported), how
///    implausible a fitted size is (Implausibility), and which experiment would separate it from
///    the causes it ties with (SeparationAdvice).
/// Entries are stateless and const; the table owns one of each.

#include <Eigen/Core>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "sim/effect.h"
#include "sim/gyro.h"

namespace rlg::diagnosis {

/// How a fit treats one parameter of an effect. A parameter the physics marks as a reference
/// (sim::EffectParameter::reference) is held at its start and left out of the report.
struct ParameterSearch {
  enum class Fit {
    kSize,   ///< fitted; the screening step scales it (the effect's strength)
    kShape,  ///< fitted from its start, not scaled by the screening step (a missing mass's
             ///< capacity, which trades against its conductance)
  };
  /// Inside the parameter's plausible range: where the screening simulation starts (thermal
  /// and sensor effects: small enough to be linear, large enough to be far above round-off in
  /// the simulated temperatures); for bias effects, which are fitted linearly, a typical size.
  double start = 0.0;
  Fit fit = Fit::kSize;
  /// > 0: a kShape parameter is held with a log-normal prior of this factor (1 sd) around
  /// `start`; 0: no prior.
  double prior_factor = 0.0;
};

/// Where an effect's candidate targets are drawn from.
struct TargetSpace {
  /// The model as it stands: its links, sources, sensors and bias terms decide what is new.
  const sim::GyroConfig& gyro;
  /// Only the first `nodes` nodes are candidates: nodes an effect added (a missing mass) are
  /// not the nominal gyro's.
  int nodes = 0;
  /// Sensor channels with data, sorted.
  std::vector<std::string> channels;
};

/// Node temperatures (°C) and rates (°C/s) of one run, nodes x samples (fit-block means).
struct NodeTrack {
  const Eigen::MatrixXd& T;
  const Eigen::MatrixXd& Tdot;
};

/// A bias effect on one target as a regressor of the linear bias fit.
struct BiasRegressor {
  std::string target;
  /// The effect's term at unit coefficient at sample k of run `run`. Terms without history
  /// (a rate, a gradient) read `track`; terms with history (hysteresis, mode hops) were
  /// computed once, from the tracks Regressors was given.
  std::function<double(const NodeTrack& track, size_t k, int run)> column;
  /// The parameters reported for a fitted coefficient of the column.
  std::function<sim::ParameterMap(double coefficient)> parameters;
  /// Parameters of the column's shape searched on the data (a mode hop's spacing, range and
  /// centre): counted with the coefficient in the information criterion.
  int searched_parameters = 0;
};

/// A candidate column: per run, one value per sample of the tracks the regressors were given.
using RunColumn = std::vector<std::vector<double>>;

/// How much a candidate column explains of what the model leaves: the drop of the residual sum
/// of squares of the in-sample bias fit when the column is added (larger is better, >= 0).
class ColumnGain {
 public:
  virtual ~ColumnGain() = default;
  virtual double operator()(const RunColumn& column) const = 0;
  /// The gain of the column `make` returns, or -1 when it returns none. `key` names that
  /// column: the same key makes the same column from the same tracks (a shape's parameters). A
  /// gain asked for the same keys again on the same tracks and regressors (a shape search's
  /// grid in each replicate of the bias null bootstrap) may keep what it needs of each key's
  /// column and skip `make`; this one makes it every time.
  virtual double Keyed(const std::vector<double>& /*key*/, const std::function<std::optional<RunColumn>()>& make) const {
    const std::optional<RunColumn> column = make();
    return column ? (*this)(*column) : -1.0;
  }
};

/// A ColumnGain that is a function of the column (keeps nothing).
class GainOfColumn final : public ColumnGain {
 public:
  explicit GainOfColumn(std::function<double(const RunColumn&)> gain) : gain_(std::move(gain)) {}
  double operator()(const RunColumn& column) const override { return gain_(column); }

 private:
  std::function<double(const RunColumn&)> gain_;
};

class EffectSearch {
 public:
  virtual ~EffectSearch() = default;
  EffectSearch(const EffectSearch&) = delete;
  EffectSearch& operator=(const EffectSearch&) = delete;

  /// The effect's physics: name, kind, parameters with their ranges, Apply.
  const sim::Effect& effect() const { return effect_; }
  const std::string& name() const { return effect_.name(); }
  /// How a fit treats the effect's parameter `name` (one of effect().parameters()).
  const ParameterSearch& Parameter(const std::string& name) const;
  /// Held at its start and not reported: a reference of the form.
  bool Fixed(const std::string& name) const;
  /// Every parameter at its start value.
  sim::ParameterMap Start() const;
  /// True when the effect's size (its kSize parameters) may take either sign.
  bool SizeIsSigned() const;
  /// `p` without the fixed parameters: what a report shows.
  sim::ParameterMap Reported(sim::ParameterMap p) const;

  /// Targets the effect can act on in `space`, in a fixed order: what `diagnose` tries.
  virtual std::vector<std::string> Targets(const TargetSpace& space) const = 0;
  /// Bias effects: a regressor per target of `space`, from the node tracks of every run. An
  /// effect whose term has a shape beyond its linear coefficient (a mode hop's spacing, centre
  /// and range) searches it by `gain` and returns its best. Empty for thermal and sensor effects.
  virtual std::vector<BiasRegressor> Regressors(const TargetSpace& space,
                                                const std::vector<const Eigen::MatrixXd*>& T_runs,
                                                const ColumnGain& gain) const;
  /// Bias effects whose term is a function of temperature tracks alone, no parameter of the
  /// gyro file's bias physics (a rate, a gradient, hysteresis; not a mode hop, which needs the
  /// cavity's length and expansion): what `diagnose` tries on measured channels when it has no
  /// thermal network (diagnosis/without_network/candidates.h). False for every other effect.
  virtual bool ComputedFromTracks() const { return false; }
  /// The parameters to apply for those a fit reports: the same, except where only a
  /// combination is identifiable (hysteresis).
  virtual sim::ParameterMap FromReported(const sim::ParameterMap& reported) const { return reported; }
  /// The parameters of a fit's report (mapped by FromReported to what Apply takes) that lie
  /// outside their plausible range, in parameter order. Empty: the effect is plausible at this
  /// size. Not empty: the fit put it at a size no such cause has: a direction the data leave
  /// unbounded, or the cause stands in for something else.
  std::vector<sim::RangeViolation> OutsidePlausibleRange(const sim::ParameterMap& reported) const;
  /// |reported main parameter| over its typical size [est], to rank candidates that explain
  /// the data equally well; 1 for effects without one.
  virtual double Implausibility(const sim::ParameterMap& reported) const;
  /// What experiment separates this effect from the others within a tie (causes of the tied
  /// candidates, this one among them); empty when the general advice for its kind applies.
  virtual std::string SeparationAdvice(const std::set<std::string>& tied_causes, bool ambient_logged) const;

 protected:
  /// The search of the catalog's effect `effect_name`, its parameters' treatment by name (every
  /// parameter of the effect but the references).
  EffectSearch(const std::string& effect_name, std::map<std::string, ParameterSearch> parameters);
  /// |reported[key]| / typical, or 1 when the fit reported no `key`.
  static double Relative(const sim::ParameterMap& reported, const std::string& key, double typical);

 private:
  const sim::Effect& effect_;
  std::map<std::string, ParameterSearch> parameters_;
};

/// Every effect's search, in catalog order (sim::Effects()'s).
const std::vector<std::unique_ptr<const EffectSearch>>& EffectSearches();

/// The search of the effect named `name`, or nullptr (a cause outside the catalog: a term of
/// the model family tried without a thermal network).
const EffectSearch* FindSearch(const std::string& name);

/// The search of the effect named `name`; InputError naming the catalog for an unknown name.
const EffectSearch& RequireSearch(const std::string& name);

/// Whether a fit of `cause` reporting `parameter` at `size`, of either sign, with the other
/// reported parameters as in `at`, lies inside the catalog's plausible range
/// (EffectSearch::OutsidePlausibleRange empty). A size that is not finite (none) and a cause
/// outside the catalog count as inside.
bool PlausibleSize(const std::string& cause, const sim::ParameterMap& at, const std::string& parameter, double size);

}  // namespace rlg::diagnosis
