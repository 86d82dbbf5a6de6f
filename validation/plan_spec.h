#pragma once
/// A calibration-protocol plan (`rlgtherm plan PLAN.toml`, docs/plan.md): a gyro or a population
/// of gyros, the compensation model to fit, the service conditions it meets in use (never used
/// for fitting), a target, and candidate protocols for the thermal chamber.
///
///   gyro = "gyros/default.toml"     # relative to the plan file
///   seed = 1
///   gyros = 200                     # without [population]: the nominal gyro, its noise alone
///   [population]                    # or a part-to-part spread (sim/population.h); count = gyros
///   [model]                         # as `fit --model` (model/fit_model.h); default Eq. (2)
///   name = "guo2006"                # pair, method, b0_window_s, channel, order, terms, offset, reference_C
///   [target]
///   p95_abs_bias_after_dph = 0.01   # required
///   [screen]
///   keep = 0                        # simulate the K candidates the screen ranks best (0: all)
///   [chamber]                       # what the built-in candidates are made of
///   span_C = [-30, 50]              # the calibration span
///   settle_h = 3                    # chamber time before each run (the gyro soaks unpowered)
///   ramp_C_per_min = 1              # heating-ramp, cooling-ramp
///   [[service]]                     # one run the gyro meets in use
///   id = "soak+60"
///   start_C = 60
///   [[candidates]]
///   name = "paper-nine-soaks"       # a built-in, by name
///   [[candidates]]
///   name = "five-soaks-1h"          # a protocol of one's own
///   soaks_C = [-30, -10, 10, 30, 50]
///   duration_s = 3600
///   [[candidates.runs]]             # and/or general runs
///   start_C = -30
///   end_C = 50
///   rate_C_per_min = 0.25
///
/// A run, in the chamber or in service (ChamberRun): the gyro is powered on at t = 0 with the
/// chamber at start_C, soaked there (or at power_on_C: a gyro taken from a freezer). The
/// ambient holds start_C for dwell_s, then ramps at rate_C_per_min (°C/min, > 0; the
/// direction is the sign of end_C - start_C) to end_C and holds it: a soak when end_C is
/// start_C. duration_s defaults to 7,200 s for a soak and dwell + ramp + hold_s for a ramp.
/// Its chamber hours are settle_h + duration_s / 3600: settling before power-on is chamber
/// time, but is not simulated (the gyro starts soaked).
///
/// A chamber cycle (cycle_C, instead of start_C and end_C) is one run, one power-on and one
/// settling: the ambient holds cycle_C[0] for dwell_s, then moves at rate_C_per_min to each
/// next point of cycle_C in turn, holding each interior point for stop_s, and holds the last:
///   [[candidates.runs]]
///   cycle_C = [-30, 50, -30]      # heat to +50 °C and cool back, in one power-on
///   rate_C_per_min = 1
///   stop_s = 1800                 # at +50 °C
///   hold_s = 1800                 # at -30 °C after the cycle
/// It must reverse at least once (a list that only rises or only falls is a ramp), consecutive
/// points differ, and duration_s defaults to dwell + the segments + stop_s at each interior
/// point + hold_s. A heating and a cooling ramp as two runs (two-ramps) pay settle_h twice.
///
/// Built-in candidates (BuiltinCandidate), with [chamber]'s span [lo, hi], settle_h and ramp rate:
///   paper-nine-soaks  the seed paper's warm-ups after soaks at -30, -20, ..., +50 °C, 2 h each
///   d-optimal-3       soaks at lo, (lo + hi)/2 and hi, 2 h each: the D-optimal design on an
///                     interval for coefficients quadratic in T10 (the ends and the middle)
///   px4-cold-warm     PX4's: a cold soak at lo, then a slow warm-up (0.25 °C/min) over
///                     max(hi - lo, 24) °C with the gyro powered, 30 min at the end
///   heating-ramp      soaked at lo, powered on, ramp to hi at ramp_C_per_min, 30 min at hi
///   cooling-ramp      soaked at hi, powered on, ramp to lo at ramp_C_per_min, 30 min at lo
///   two-ramps         heating-ramp and cooling-ramp, two power-ons
///   chamber-cycle     soaked at lo, powered on, a ramp to hi at ramp_C_per_min, 30 min at hi,
///                     a ramp back to lo, 30 min at lo: two-ramps' ramps in one power-on
///   d-optimal-3+ramps         d-optimal-3's soaks and two-ramps: for models with gradient
///   paper-nine-soaks+ramps    paper-nine-soaks and two-ramps     terms that hold in service
///
/// A calibration run with the same conditions as a service run is refused: the service
/// conditions score what the fit has not seen.

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "model/fit_model.h"
#include "sim/gyro.h"
#include "sim/population.h"
#include "sim/scenario.h"

namespace rlg::validation {

struct ChamberRun {
  std::string id;                      ///< service: as written; calibration: made from the conditions
  double start_C = 20.0;
  double end_C = 20.0;                 ///< = start_C: a soak
  double rate_C_per_min = 0.0;         ///< > 0 for a ramp
  double dwell_s = 0.0;                ///< at start_C before the ramp
  double hold_s = 0.0;                 ///< at end_C after the ramp (when duration_s is not given)
  /// A chamber cycle's points, in order (start_C = front, end_C = back); empty: a soak or a ramp.
  std::vector<double> cycle_C;
  double stop_s = 0.0;                 ///< a cycle's hold at each interior point
  double duration_s = 7200.0;
  double sample_period_s = 1.0;
  std::optional<double> power_on_C;    ///< the gyro's temperature at power-on; none: soaked at start_C
  double settle_h = 0.0;               ///< chamber time before power-on (not simulated)
  int line = 0;                        ///< of its table, for messages

  bool IsValid() const;
  bool IsCycle() const { return !cycle_C.empty(); }
  /// The conditions as text: equal conditions, equal text (and equal simulated data for a gyro).
  std::string Conditions() const;
  double ChamberHours() const { return settle_h + duration_s / 3600.0; }
  /// The simulator's run.
  sim::RunSpec ToRunSpec() const;
};

struct Candidate {
  std::string name;
  std::string builtin;                 ///< the built-in it was made from; empty for one's own
  std::vector<ChamberRun> runs;
  std::optional<model::FitRequest> model;  ///< none: the plan's
  int line = 0;
  double ChamberHours() const;
};

struct ChamberDefaults {
  std::array<double, 2> span_C{-30.0, 50.0};
  double settle_h = 3.0;
  double ramp_C_per_min = 1.0;
  double duration_s = 7200.0;
  double sample_period_s = 1.0;
};

struct PlanSpec {
  std::string path;
  sim::GyroConfig gyro;
  std::optional<sim::PopulationSpec> population;
  uint64_t gyros = 0;                  ///< population count, or `gyros`
  uint64_t seed = 1;
  model::FitRequest model;             ///< name resolved: never empty
  std::vector<ChamberRun> service;
  double target_p95_dph = 0.0;
  size_t screen_keep = 0;              ///< 0: every candidate is simulated
  ChamberDefaults chamber;
  std::vector<Candidate> candidates;

  bool IsValid() const;
};

/// The names BuiltinCandidate knows.
const std::vector<std::string>& BuiltinCandidateNames();
/// A built-in candidate with `chamber`'s span, settling and ramp rate; InputError for an unknown
/// name (listing the built-ins).
Candidate BuiltinCandidate(const std::string& name, const ChamberDefaults& chamber);

/// Loads a plan file and the gyro it names. InputError "FILE:LINE: ..." for anything wrong: an
/// unknown candidate name, a missing target, a service run a candidate also calibrates on, a
/// model option the model does not take.
PlanSpec LoadPlan(const std::string& path);

}  // namespace rlg::validation
