#include "diagnosis/network/metrics.h"

#include <cmath>

#include "diagnosis/network/bias_design.h"
#include "diagnosis/network/prediction.h"
#include "diagnosis/network/thermal_residuals.h"

namespace rlg::diagnosis {

Metrics Measure(const Problem& p, const Model& m) {
  Metrics out;
  const std::vector<int> all = p.All();
  const auto pred = SimulateAll(p, m, all);
  const auto res = ThermalResiduals(p, pred, all);
  for (size_t s = 0; s < p.nominal.sensors.size(); ++s) {
    double ssr = 0.0;
    int n = 0;
    for (int r : p.Scored())
      if (s < res[r].size()) ssr += ScoreSsr(p, res[r][s], r, &n);
    if (n > 0) out.temperature_rms_C[p.nominal.sensors[s].channel] = std::sqrt(ssr / n);
  }
  if (p.has_bias) out.bias_rms_dph = ScoreBias(p, HeldOutBias(p, Design(p, m, pred, {}))).rms();
  return out;
}

}  // namespace rlg::diagnosis
