// Verb compare: every model of the family on the same training and held-out data
// (compensation/model_comparison.h).

#include <CLI/CLI.hpp>
#include <fmt/format.h>
#include <memory>
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

Verb RegisterCompare(CLI::App& app) {
  auto a = std::make_shared<CompareArgs>();
  CLI::App* cmd = app.add_subcommand("compare",
                                     "fit every model on training data, score each on held-out data "
                                     "(Table 2 metrics), and select one on the training data alone");
  cmd->add_option("DATA", a->data, "tidy CSV ('-' = stdin)")->required();
  cmd->add_option("--fit-runs", a->fit_runs,
                  "runs to fit on; the others are scored whole (default: each run's "
                  "first 70 % in time fitted, the rest scored)")
      ->delimiter(',');
  cmd->add_option("--cut-at", a->cut_s,
                  "cut each run in time here (s after its first sample): fit before, score "
                  "after, the compensator running on across the cut (default: at 70 % of "
                  "each run)");
  cmd->add_option("--channel", a->channel, "temperature channel of the polynomial models")->capture_default_str();
  cmd->add_option("--pair", a->pair, "sensor pair of Eq. (2)")->capture_default_str();
  cmd->add_option("--b0-window", a->b0_window_s, "B0 window (s) of the power-on models")->capture_default_str();
  cmd->add_flag("--json", a->json, "machine-readable output (keys: docs/data-format.md)");
  cmd->add_option("--plot", a->plot,
                  "directory for figures: heldout_<model>.png, each model's held-out "
                  "compensated bias against temperature");
  return {cmd, [a] { return RunCompare(*a); }};
}

}  // namespace rlg::cli
