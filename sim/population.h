#pragma once
/// Part-to-part spread: a population of gyros drawn around a nominal gyro (docs/results.md, Populations).
///
/// A suite or scenario file's [population] table (scenarios/README.md, "Populations"):
///
///   [population]
///   count = 1000                       # gyros 0 .. count-1
///   [[population.spread]]
///   parameter = "nodes.*.heat_capacity_J_per_K"   # a name or pattern of sim/gyro_parameters.h
///   distribution = "lognormal"         # "normal", "lognormal" or "uniform"
///   relative_sigma = 0.05              # normal:    x = x0 (1 + s z)           s relative to x0
///                                      # lognormal: x = x0 exp(s z)            s of ln x
///   # sigma = 0.002                    # normal:    x = x0 + sigma z           in x's own unit
///   # range = [-0.01, 0.01]            # uniform:   x = x0 + lo + (hi - lo) Phi(z), offsets from x0
///   [[population.correlation]]
///   parameters = ["nodes.anode.heat_capacity_J_per_K", "nodes.block.heat_capacity_J_per_K"]
///   coefficient = 0.8                  # correlation of the two draws' z
///
/// z is a standard normal score per parameter; the scores of one gyro are z = L u with u
/// independent standard normals and L L^T the correlation matrix (Cholesky; a Gaussian copula,
/// so a uniform or log-normal parameter keeps its own distribution and the correlation is that
/// of the scores). A pattern spreads each parameter it matches independently, with the same
/// distribution. A parameter named by two entries, a correlation between parameters no entry
/// spreads, or a correlation matrix that is not positive definite is refused with the file and
/// line.
///
/// Gyro i, reproducibly and alone: its seed is GyroSeed(suite seed, i) (SplitMix64 of both), its
/// scores u are the first draws of Rng(seed_i, kParameterStream), and its runs are simulated
/// with seed_i on their usual streams (the run's index), so gyro i is the same gyro, with the
/// same noise, whether it is simulated alone, first, or as one of 10,000 on any number of
/// threads. A draw outside the parameter's physical range (a heat capacity <= 0, a negative
/// noise level, a play's width <= 0 or an effect parameter beyond what a gyro file may give,
/// sim/gyro_parameters.h) is an InputError naming the gyro, the parameter and the value: the spread
/// written is too wide for the distribution chosen (use "lognormal" for what must stay positive).

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "sim/gyro.h"
#include "sim/gyro_parameters.h"

namespace rlg::sim {

struct Spread {
  enum class Kind { kNormal, kLogNormal, kUniform };
  std::string parameter;  ///< name or pattern, as written
  Kind kind = Kind::kNormal;
  double relative_sigma = 0.0;  ///< normal (when sigma is 0) and lognormal
  double sigma = 0.0;           ///< normal, absolute
  double lo = 0.0, hi = 0.0;    ///< uniform, offsets from the nominal
  int line = 0;                 ///< of the entry, for messages
};

struct Correlation {
  std::string a, b;
  double coefficient = 0.0;
  int line = 0;
};

struct PopulationSpec {
  std::string file;  ///< the file holding [population], for messages
  uint64_t count = 0;
  std::vector<Spread> spreads;
  std::vector<Correlation> correlations;

  /// True when count >= 1 and every spread is well formed (a sigma >= 0, lo <= hi, |rho| < 1).
  bool IsValid() const;
};

/// The spread parameters of one nominal gyro, resolved once: the parameters each entry stands
/// for, and the Cholesky factor of their scores' correlation. InputError (with the spec's file
/// and the entry's line) for a pattern that matches nothing, a parameter spread twice, a
/// correlation naming an unspread parameter, or a correlation matrix that is not positive
/// definite.
class Population {
 public:
  Population(const PopulationSpec& spec, const GyroConfig& nominal);

  /// Random stream of the parameter draws: apart from the run streams (a run's index).
  static constexpr uint64_t kParameterStream = uint64_t{1} << 32;
  /// Seed of gyro i in a population simulated with `suite_seed` (SplitMix64 of both).
  static uint64_t GyroSeed(uint64_t suite_seed, uint64_t i);

  struct Gyro {
    uint64_t index = 0;
    uint64_t seed = 0;
    GyroConfig config;
    std::vector<double> values;  ///< per parameter(), in its order
  };
  /// Gyro i (i < count).
  Gyro Draw(uint64_t suite_seed, uint64_t i) const;

  uint64_t count() const { return spec_.count; }
  /// Names of the spread parameters, in the order of Gyro::values (the per-gyro CSV's columns).
  const std::vector<std::string>& parameters() const { return names_; }
  const std::vector<double>& nominal_values() const { return nominal_; }
  const GyroConfig& nominal() const { return nominal_gyro_; }

 private:
  PopulationSpec spec_;
  GyroConfig nominal_gyro_;
  std::vector<GyroParameter> params_;
  std::vector<const Spread*> spread_of_;  // per parameter
  std::vector<std::string> names_;
  std::vector<double> nominal_;
  std::vector<double> cholesky_;  // lower triangle, row-major n x n; empty without correlations
};

}  // namespace rlg::sim
