#include "tools/rlgtherm/report_figures.h"

#include <filesystem>
#include <fmt/format.h>

#include "tools/rlgtherm/plot_kit.h"

namespace rlg::cli {
namespace {

using plot::kBlack;
using plot::kBlue;
using plot::kGrey;
using plot::kRed;

/// The models shown above a panel: "measured" (where drawn), the calibrated nominal, and the
/// extended model when a step was accepted.
void ModelLegend(plot::Page& page, bool measured, bool extended) {
  std::vector<std::pair<plot::Colour, std::string>> entries;
  if (measured) entries.emplace_back(kBlack, "measured");
  entries.emplace_back(kRed, "calibrated nominal");
  if (extended) entries.emplace_back(kBlue, "extended (accepted effects)");
  page.Legend(entries);
}

void WriteChannelFigure(const std::string& path, const diagnosis::ChannelFigure& f, bool extended, double score_block_s) {
  const std::string& ch = f.channel;
  const std::string& temperature = f.temperature;
  const bool bias = ch == "bias_dph";
  const std::string unit = bias ? "°/h" : "°C";
  // Runs end to end on one time axis (h), with a small gap between them.
  std::vector<std::vector<double>> hours, measured, sim_base, sim_ext, res_hours, res_base, res_ext, temp, rate;
  std::vector<std::pair<double, std::string>> starts;
  double offset = 0.0;
  for (const auto& run : f.runs) {
    const size_t n = run.t_s.size();
    std::vector<double> h(n);
    for (size_t i = 0; i < n; ++i) h[i] = offset + (run.t_s[i] - run.t_s.front()) / 3600.0;
    starts.emplace_back(offset, run.run);
    offset = h.back() + 0.02 * (h.back() - offset) + 1e-3;
    hours.push_back(h);
    measured.push_back(run.measured);
    sim_base.push_back(run.simulated_baseline);
    sim_ext.push_back(run.simulated_extended);
    res_hours.push_back(diagnosis::GroupMeans(h, run.blocks_per_score_block));
    res_base.push_back(run.residual_baseline);
    res_ext.push_back(run.residual_extended);
    temp.push_back(run.temperature_C);
    rate.push_back(run.rate_C_per_min);
  }
  if (hours.empty()) return;
  plot::Range rx, ry, rr, rt, rdt;
  for (size_t k = 0; k < hours.size(); ++k) {
    rx.Add(hours[k]);
    ry.Add(measured[k]);
    ry.Add(sim_base[k]);
    rr.Add(res_base[k]);
    rt.Add(temp[k]);
    rdt.Add(rate[k]);
    if (extended) ry.Add(sim_ext[k]), rr.Add(res_ext[k]);
  }
  const auto x = rx.Padded(), y = ry.Padded(), r = rr.Padded();
  size_t points = 0;
  for (const auto& v : res_base) points += v.size();
  const bool sparse = points < 1000;

  plot::Page page(path, 1400, 900, 2, 2);

  page.Frame(1, x, y, "time, runs end to end (h)", fmt::format("{} ({})", ch, unit),
             fmt::format("{}: data and model (fit-block means)", ch));
  ModelLegend(page, true, extended);
  page.RunSeparators(starts);
  for (size_t k = 0; k < hours.size(); ++k) {
    page.Curve(kBlack, hours[k], measured[k]);
    page.Curve(kRed, hours[k], sim_base[k]);
    if (extended) page.Curve(kBlue, hours[k], sim_ext[k]);
  }

  page.Frame(2, x, r, "time, runs end to end (h)", fmt::format("residual ({})", unit),
             fmt::format("{}: measured - simulated, {:.3g} s means{}", ch, score_block_s, bias ? ", held out" : ""));
  ModelLegend(page, false, extended);
  page.RunSeparators(starts);
  for (size_t k = 0; k < hours.size(); ++k) {
    page.Curve(kRed, res_hours[k], res_base[k]);
    if (extended) page.Curve(kBlue, res_hours[k], res_ext[k]);
  }
  page.Curve(kGrey, {x.first, x.second}, {0.0, 0.0});

  page.Frame(3, rt.Padded(), r, fmt::format("{} (°C)", temperature), fmt::format("residual ({})", unit),
             fmt::format("{} residual against temperature", ch));
  ModelLegend(page, false, extended);
  for (size_t k = 0; k < hours.size(); ++k) {
    page.Dots(kRed, temp[k], res_base[k], sparse);
    if (extended) page.Dots(kBlue, temp[k], res_ext[k], sparse);
  }

  page.Frame(4, rdt.Padded(), r, fmt::format("d{}/dt (°C/min)", temperature), fmt::format("residual ({})", unit),
             fmt::format("{} residual against the rate of {}", ch, temperature));
  ModelLegend(page, false, extended);
  for (size_t k = 0; k < hours.size(); ++k) {
    page.Dots(kRed, rate[k], res_base[k], sparse);
    if (extended) page.Dots(kBlue, rate[k], res_ext[k], sparse);
  }
}  // ~Page ends the stream and closes the file

}  // namespace

void WriteDiagnosisFigures(io::OutputDirectory& report, const diagnosis::DiagnosisFigures& figures) {
  plot::RequirePngCairo("diagnose --report");
  for (const auto& figure : figures.channels) {
    const std::string name = "fit_" + figure.channel + ".png";
    const std::string path = report.Stage(name);
    WriteChannelFigure(path, figure, figures.extended, figures.score_block_s);
    if (!std::filesystem::exists(path)) continue;  // no run has this channel; Commit skips it
    plot::CheckPngComplete(path, report.dir() + "/" + name, report.NothingWritten());
  }
}

}  // namespace rlg::cli
