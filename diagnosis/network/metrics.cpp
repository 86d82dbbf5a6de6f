#include "diagnosis/network/metrics.h"

#include <cmath>

#include "diagnosis/network/model_residuals.h"

namespace rlg::diagnosis {

Metrics Measure(const Problem& p, const Model& m) {
  Metrics out;
  const ModelResiduals res = ResidualsOf(p, m);
  for (size_t s = 0; s < p.nominal.sensors.size(); ++s) {
    double ssr = 0.0;
    int n = 0;
    for (int r : p.Scored())
      if (s < res.thermal[r].size()) ssr += ScoreSsr(p, res.thermal[r][s], r, &n);
    if (n > 0) out.temperature_rms_C[p.nominal.sensors[s].channel] = std::sqrt(ssr / n);
  }
  if (p.has_bias) out.bias_rms_dph = ScoreBias(p, res.bias).rms();
  return out;
}

}  // namespace rlg::diagnosis
