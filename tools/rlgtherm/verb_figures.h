#pragma once
// PNG figures of `--plot DIR` (compensate, evaluate, validate, allan, compare): one figure per concept,
// drawn from the numbers the verbs' reports computed, never recomputing a reported number.
//   bias_<run>.png   bias before and after compensation over time (block means), the
//                    compensated bias alone on its own scale, and the run's temperatures
//   allan_<run>.png  Allan deviation (log-log) with the noise lines of the terms the read-off
//                    resolved, each marked where it is read; unresolved terms are named with
//                    their upper bound and get no line
//   table1.png       the Table 1 analogue: SSE_ave of M1..M6 (and the paper's, when the suite
//                    has them)
//   heldout_<model>.png  compare: a model's held-out compensated bias against temperature
//   pareto.png       plan: chamber hours against the predicted p95 |bias after| of each
//                    candidate, with its 90 % interval, the Pareto front and the target

#include <map>
#include <string>
#include <vector>

#include "io/atomic_output.h"
#include "model/allan.h"
#include "model/pairs.h"
#include "sim/trace.h"

namespace rlg::cli {

/// A figure directory: DIR made whole or not at all (io::OutputDirectory, named "--plot" and
/// "figures" in its messages). Created at construction, so that an unusable DIR (InputError,
/// exit 2) or PLplot without its pngcairo device (InputError) is refused before any work.
/// Each Write* stages one PNG and checks it is whole (OutputError naming it otherwise); Commit
/// moves them all into DIR. Two runs whose ids map to the same file name get "-2", "-3" ...
class FigureDirectory {
 public:
  explicit FigureDirectory(const std::string& dir);

  /// bias_<run><suffix>.png of one run: `before` and `after` (°/h, one value per sample of
  /// `run`) as block means of about 100 s (at least one sample; the title says which), the
  /// after alone, and every temperature channel of the run (names starting with T).
  /// `after_label` names the compensated series in the legend.
  void WriteBias(const sim::Run& run, const std::vector<double>& before, const std::string& before_label,
                 const std::vector<double>& after, const std::string& after_label, const std::string& suffix = "");

  /// allan_<run><suffix>.png: the curve of `series` (its name in the title) and its read-offs.
  void WriteAllan(const std::string& run, const std::string& series, const model::AllanCurve& curve,
                  const model::NoiseReadOffs& readoffs, const std::string& suffix = "");

  /// table1.png: SSE_ave ((°/h)²) of each combination, bars labelled by name and pair; the
  /// paper's values beside them where `paper` has the name; `average_s` > 0 states the means
  /// the scores were computed on.
  void WriteTable1(const std::vector<model::PairScore>& scores, const std::map<std::string, double>& paper,
                   double average_s);

  /// heldout_<label>.png: a model's compensated bias on the held-out samples against the
  /// temperature `channel` (°C), every sample a dot and the means of 1/40 of the range in a line
  /// (`compare --plot`); `title` says which model and data.
  void WriteResidualVsTemperature(const std::string& label, const std::string& title, const std::string& channel,
                                  const std::vector<double>& T, const std::vector<double>& residual);

  /// One candidate of `plan` on pareto.png.
  struct PlanPoint {
    std::string name;
    double chamber_h = 0.0, p95 = 0.0;
    double lo = 0.0, hi = 0.0;  ///< the 90 % interval; lo <= 0 or hi infinite: open on that side
    bool pareto = false, recommended = false;
  };
  /// pareto.png: p95 |bias after| (°/h, log axis) against chamber hours, each candidate with
  /// its interval, the front joined, the recommended one ringed, the target a dashed line.
  void WritePareto(const std::vector<PlanPoint>& points, double target_dph, const std::string& title);

  /// Moves the figures into DIR and says so on stderr (stdout stays what it is without --plot).
  void Commit();

 private:
  /// A staged path for `stem`.png, unique within this directory; `name` gets the file name.
  std::string Stage(const std::string& stem, std::string& name);
  void Check(const std::string& path, const std::string& name);

  io::OutputDirectory dir_;
  std::vector<std::string> names_;
};

}  // namespace rlg::cli
