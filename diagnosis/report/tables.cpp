// The residual table and the figures' data of a diagnosis (report.h).

#include "diagnosis/report.h"

#include <algorithm>
#include <cmath>
#include <fmt/format.h>
#include <limits>

namespace rlg::diagnosis {

std::vector<double> RatePerMinute(const std::vector<double>& t, const std::vector<double>& T) {
  std::vector<double> r(T.size(), std::numeric_limits<double>::quiet_NaN());
  if (T.size() < 2) return r;
  for (size_t i = 0; i < T.size(); ++i) {
    const size_t a = i == 0 ? 0 : i - 1, b = std::min(i + 1, T.size() - 1);
    r[i] = 60.0 * (T[b] - T[a]) / (t[b] - t[a]);
  }
  return r;
}

std::vector<double> GroupMeans(const std::vector<double>& v, size_t g) {
  std::vector<double> out;
  for (size_t i = 0; i + g <= v.size(); i += g) {
    double sum = 0.0;
    for (size_t k = i; k < i + g; ++k) sum += v[k];
    out.push_back(sum / static_cast<double>(g));
  }
  return out;
}

std::string BiasTemperatureChannel(const sim::GyroConfig& gyro) {
  for (const auto& s : gyro.sensors)
    if (s.node == gyro.bias.node) return s.channel;
  return gyro.sensors.front().channel;
}

namespace {

/// The report's channels: those of the first run's residuals, in name order.
std::vector<std::string> ReportChannels(const SearchRecord& d) {
  std::vector<std::string> channels;
  if (!d.residuals.empty())
    for (const auto& [ch, v] : d.residuals.front().measured) channels.push_back(ch);
  return channels;
}

/// Some run has the baseline's residuals of channel `ch` (every channel of a diagnosis against a
/// gyro; only the bias without a thermal network).
bool Modelled(const SearchRecord& d, const std::string& ch) {
  return std::any_of(d.residuals.begin(), d.residuals.end(), [&ch](const ResidualTrace& tr) { return tr.baseline.count(ch) > 0; });
}

std::vector<double> Head(const std::vector<double>& v, size_t n) {
  return {v.begin(), v.begin() + static_cast<std::ptrdiff_t>(n)};
}

}  // namespace

ResidualTable MakeResidualTable(const SearchRecord& d) {
  using Kind = ResidualColumn::Kind;
  ResidualTable table;
  const std::vector<std::string> channels = ReportChannels(d);
  for (const auto& ch : channels) {
    table.columns.push_back({"measured_" + ch, ch, Kind::kMeasured});
    if (ch != "bias_dph") table.columns.push_back({"dTdt_" + ch + "_C_per_min", ch, Kind::kRate});
    if (!Modelled(d, ch)) continue;  // measured only (a temperature without a thermal network)
    table.columns.push_back({"baseline_" + ch, ch, Kind::kBaseline});
    table.columns.push_back({"extended_" + ch, ch, Kind::kExtended});
  }
  for (const auto& tr : d.residuals) {
    ResidualTableRun run;
    run.run = tr.run;
    run.t_s = tr.t_s;
    for (const auto& column : table.columns) {
      const std::string& ch = column.channel;
      const auto m = tr.measured.find(ch), b = tr.baseline.find(ch), e = tr.extended.find(ch);
      const bool modelled = b != tr.baseline.end() && e != tr.extended.end();
      std::vector<double> values;
      if (m != tr.measured.end() && !modelled) {  // data only: a channel no model predicts, or unscored stretches
        const size_t n = std::min(tr.t_s.size(), m->second.size());
        if (column.kind == Kind::kMeasured) values = Head(m->second, n);
        if (column.kind == Kind::kRate) values = Head(RatePerMinute(tr.t_s, m->second), n);
      } else if (m != tr.measured.end()) {
        const size_t n = std::min({tr.t_s.size(), m->second.size(), b->second.size(), e->second.size()});
        switch (column.kind) {
          case Kind::kMeasured: values = Head(m->second, n); break;
          case Kind::kRate: values = Head(RatePerMinute(tr.t_s, m->second), n); break;
          case Kind::kBaseline: values = Head(b->second, n); break;
          case Kind::kExtended: values = Head(e->second, n); break;
        }
      }
      run.values.push_back(std::move(values));
    }
    table.runs.push_back(std::move(run));
  }
  return table;
}

DiagnosisFigures MakeDiagnosisFigures(const SearchRecord& d, const std::string& bias_temperature) {
  DiagnosisFigures figures;
  figures.score_block_s = d.score_block_s.second;
  figures.extended = !d.steps.empty();
  for (const auto& ch : ReportChannels(d)) {
    if (!Modelled(d, ch)) continue;  // no model of it to show (a temperature without a thermal network)
    ChannelFigure figure;
    figure.channel = ch;
    figure.temperature = ch == "bias_dph" ? bias_temperature : ch;
    for (const auto& tr : d.residuals) {
      const auto m = tr.measured.find(ch), b = tr.baseline.find(ch), e = tr.extended.find(ch);
      const auto T = tr.measured.find(figure.temperature);
      if (m == tr.measured.end() || b == tr.baseline.end() || e == tr.extended.end() || T == tr.measured.end()) continue;
      const size_t n = std::min({m->second.size(), b->second.size(), e->second.size(), T->second.size(), tr.t_s.size()});
      if (n == 0) continue;
      ChannelFigureRun run;
      run.run = tr.run;
      run.t_s = Head(tr.t_s, n);
      run.measured = Head(m->second, n);
      run.simulated_baseline.resize(n);
      run.simulated_extended.resize(n);
      for (size_t i = 0; i < n; ++i) {
        run.simulated_baseline[i] = m->second[i] - b->second[i];
        run.simulated_extended[i] = m->second[i] - e->second[i];
      }
      const double spacing = n > 1 ? (tr.t_s[n - 1] - tr.t_s[0]) / static_cast<double>(n - 1) : figures.score_block_s;
      const size_t g = static_cast<size_t>(std::max(1.0, std::round(figures.score_block_s / spacing)));
      run.blocks_per_score_block = g;
      const std::vector<double> temperature = Head(T->second, n);
      run.residual_baseline = GroupMeans(Head(b->second, n), g);
      run.residual_extended = GroupMeans(Head(e->second, n), g);
      run.temperature_C = GroupMeans(temperature, g);
      run.rate_C_per_min = GroupMeans(RatePerMinute(run.t_s, temperature), g);
      figure.runs.push_back(std::move(run));
    }
    figures.channels.push_back(std::move(figure));
  }
  return figures;
}

}  // namespace rlg::diagnosis
