// Verb compare: every model of the family on the same training and held-out data
// (compensation/model_comparison.h).

#include <fmt/format.h>
#include <nlohmann/json.hpp>
#include <optional>
#include <unistd.h>

#include "compensation/model_comparison.h"
#include "sim/errors.h"
#include "tools/rlgtherm/commands.h"
#include "tools/rlgtherm/common.h"
#include "tools/rlgtherm/verb_figures.h"

namespace rlg::cli {

int RunCompare(const CompareArgs& a) {
  // The figure directory first: an unusable DIR is refused before any work.
  std::optional<FigureDirectory> figures;
  if (!a.plot.empty()) figures.emplace(a.plot);
  const sim::Trace trace = LoadData(a.data);
  trace.Select(a.fit_runs);  // an unknown run is refused naming the runs there are
  compensation::ComparisonOptions o;
  o.fit_runs = a.fit_runs;
  o.channel = a.channel;
  o.pair = ParsePair(a.pair);
  o.b0_window_s = a.b0_window_s;
  o.train_fraction = a.train_fraction;
  o.cut_s = a.cut_s;
  // Progress on stderr when it is a terminal (docs/cli.md), one line rewritten in place.
  const bool tty = ::isatty(STDERR_FILENO);
  if (tty) o.progress = [](const std::string& what) { fmt::print(stderr, "\rcompare: {}\x1b[K", what); };
  const compensation::Comparison c = NamingFile(a.data, [&] { return compensation::CompareModels(trace, o); });
  if (tty) fmt::print(stderr, "\r\x1b[K");
  // Everything is computed and drawn before anything is printed.
  if (figures) {
    for (const auto& m : c.models) {
      if (!m.fitted) continue;
      figures->WriteResidualVsTemperature(
          m.label, fmt::format("{}: held-out compensated bias, {:.4f} °/h RMS (trained on other data)", m.label, m.heldout_rms_dph),
          model::ModelChannels(*m.fitted).front(), m.heldout_T, m.heldout_residual);
    }
    figures->Commit();
  }
  if (a.json) {
    fmt::print("{}\n", compensation::ComparisonJson(c).dump(2));
  } else {
    fmt::print("{}", compensation::ComparisonText(c));
  }
  return 0;
}

}  // namespace rlg::cli
