#include "diagnosis/network/thermal_null.h"

#include <cmath>
#include <fmt/format.h>

#include "diagnosis/statistics/unexplained.h"
#include "sim/noise.h"

namespace rlg::diagnosis {

using sim::GyroConfig;

Eigen::MatrixXd NullThermalReplicates(const Problem& p, const Model& m, const std::vector<Prediction>& pred,
                                      const std::vector<double>& channel_var) {
  // Row layout: the thermal search's (fit runs, their sensors, their fit blocks).
  Eigen::Index n = 0;
  for (int r : p.fit)
    for (size_t s = 0; s < p.nominal.sensors.size(); ++s)
      if (p.runs[r].sensor_col[s] >= 0) n += static_cast<Eigen::Index>(p.fit_blocks[r].size());
  const int R = p.options.null_replicates;
  Eigen::MatrixXd out(n, R);
  const GyroConfig g = Build(p.nominal, p.knobs, m);
  // Per fit run, drawn from once per replicate: the logged ambient's noise per point (0 for an
  // exact record or none: p.ambient_noise) and each channel's white noise per sample.
  const std::vector<double>& ambient_sd = p.ambient_noise;
  std::vector<std::vector<double>> white(p.runs.size(), std::vector<double>(p.nominal.sensors.size(), 0.0));
  for (int r : p.fit) {
    const PreparedRun& rp = p.runs[r];
    for (size_t s = 0; s < p.nominal.sensors.size(); ++s)
      if (rp.sensor_col[s] >= 0) white[r][s] = WhiteNoiseSd(rp.run->columns[static_cast<size_t>(rp.sensor_col[s])]);
  }
  for (int b = 0; b < R; ++b) {
    Eigen::Index row = 0;
    for (int r : p.fit) {
      const PreparedRun& rp = p.runs[r];
      const sim::Run& run = *rp.run;
      // Seeds apart from the bias bootstrap's (1, 2, ...): the two draw independently.
      sim::Rng rng(0x7e5a0000u + static_cast<uint64_t>(b), static_cast<uint64_t>(r));
      // The logged ambient again: the model's curve plus fresh noise of the column's level,
      // smoothed as the data's was; exact records (no noise at every point) have no error.
      std::vector<std::vector<double>> ambient_error(p.nominal.sensors.size());
      if (const double sd = ambient_sd[r]; sd > 0.0) {
        std::vector<double> v(run.size());
        for (size_t k = 0; k < v.size(); ++k) v[k] = rp.ambient.Value(run.t_s[k]) + sd * rng.Normal();
        PreparedRun again = rp;
        again.ambient = LoggedAmbient(run.t_s, v, rp.sample_period_s, p.noise);
        try {
          const Prediction q = SimulateRun(p, g, m, again, r, Sampled::kSensors);
          for (size_t s = 0; s < p.nominal.sensors.size(); ++s)
            if (rp.sensor_col[s] >= 0)
              for (size_t i = 0; i < p.fit_blocks[r].size(); ++i)
                ambient_error[s].push_back(q.sensor[s][i] - pred[r].sensor[s][i]);
        } catch (const std::exception&) {  // a curve the simulation cannot run: white noise alone
          for (auto& e : ambient_error) e.clear();
        }
      }
      for (size_t s = 0; s < p.nominal.sensors.size(); ++s) {
        if (rp.sensor_col[s] < 0) continue;
        const double unit = std::sqrt(channel_var[s]);
        for (size_t i = 0; i < p.fit_blocks[r].size(); ++i) {
          const auto [from, to] = p.fit_blocks[r][i];
          double e = white[r][s] / std::sqrt(static_cast<double>(to - from)) * rng.Normal();
          if (!ambient_error[s].empty()) e += ambient_error[s][i];
          out(row++, b) = e / unit;
        }
      }
    }
  }
  return out;
}

std::string ThermalNullNote(const Problem& p, const NullBootstrap& null) {
  return fmt::format("thermal acceptance: score >= {:.1f}, the best thermal candidate's screening score on {} null "
                     "replicates (the calibrated model's residuals on data it made: each channel's white noise{}); the "
                     "information criterion alone asks {:.0f}",
                     null.threshold, null.replicates,
                     p.has_logged_ambient ? " and the error of the curve through the logged ambient's noise" : "",
                     p.options.min_score);
}

}  // namespace rlg::diagnosis
