#pragma once
/// The one record every stage reads and writes: runs of time-stamped channels, simulated or
/// measured. Units live in the column names (docs/data-format.md): t_s in s, T* in °C, bias_dph in
/// °/h, P_<source>_W in W.

#include <deque>
#include <string>
#include <vector>

namespace rlg::sim {

struct Run {
  std::string id;
  std::string source;  ///< file the run was read or simulated from ("<stdin>"); empty if made in memory
  int first_line = 0;  ///< line of its first row in `source`; 0 when not from a data file
  std::vector<double> t_s;
  std::vector<std::string> names;             ///< data columns after t_s, in file order
  std::deque<std::vector<double>> columns;    ///< columns[i] belongs to names[i]; a deque so that
                                              ///< references from AddColumn stay valid

  size_t size() const { return t_s.size(); }
  /// (last time - first time) / (samples - 1), s; 0 with fewer than two samples.
  double MeanSamplePeriod() const {
    return size() > 1 ? (t_s.back() - t_s.front()) / static_cast<double>(size() - 1) : 0.0;
  }
  /// Where the run came from, to begin a message about it: "data.csv:12: run 'a'" (the line of
  /// its first row), "scenario.toml: run 'a'", or "run 'a'" for a run made in memory.
  std::string Where() const;
  /// Index of column `name`, or -1.
  int Find(const std::string& name) const;
  bool Has(const std::string& name) const { return Find(name) >= 0; }
  /// Column `name`; InputError naming the run if absent.
  const std::vector<double>& Column(const std::string& name) const;
  /// Appends an empty column (reserve()d to the run length) and returns it; the reference
  /// stays valid when more columns are added.
  std::vector<double>& AddColumn(const std::string& name);
};

struct Trace {
  std::string source;                 ///< file the trace was read from; empty if made in memory
  std::vector<std::string> comments;  ///< header comment lines, without the leading '#'
  std::vector<Run> runs;

  /// Run `id`; InputError listing the available ids if absent.
  const Run& FindRun(const std::string& id) const;
  /// The runs named in `ids`, in that order (every run, in file order, when empty);
  /// InputError naming an unknown id and the runs there are.
  std::vector<const Run*> Select(const std::vector<std::string>& ids) const;
};

/// Means over consecutive blocks of `period_s` (the paper logged one value per minute); the
/// time of a block is the mean of its sample times. A last, shorter block is kept.
Run BlockMeans(const Run& run, double period_s);
/// Copies of `runs`, each replaced by its BlockMeans over `period_s` (a copy as it is when 0).
std::vector<Run> BlockAveraged(const std::vector<const Run*>& runs, double period_s);
/// Pointers to the runs of `runs`, for the fits that take `const Run*`.
std::vector<const Run*> Pointers(const std::vector<Run>& runs);

/// A cut inside a run: the index of its first sample at least `since_start_s` after its first
/// sample (size() when none is).
size_t FirstSampleAt(const Run& run, double since_start_s);
/// The first `count` samples of `run`, as a run of its own: what came before a cut in time.
/// Models and compensators run over it from the same power-on, so a fit on the head is a fit
/// on the run's first part with every causal state as it was.
Run Head(const Run& run, size_t count);
/// Samples `first`.. of `run` (its first line moved along): what came after a cut.
Run Tail(const Run& run, size_t first);

}  // namespace rlg::sim
