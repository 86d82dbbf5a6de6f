#include "diagnosis/network/residual_checks.h"

#include "diagnosis/network/model_residuals.h"
#include "diagnosis/statistics/score.h"

namespace rlg::diagnosis {

ResidualChecks CheckResiduals(const Problem& p, const Model& m) {
  ResidualChecks out;
  const std::vector<int> all = p.All();
  const ModelResiduals res = ResidualsOf(p, m);
  for (size_t s = 0; s < p.nominal.sensors.size(); ++s) {
    std::vector<double> pooled;
    for (int r : all)
      if (s < res.thermal[r].size()) pooled.insert(pooled.end(), res.thermal[r][s].begin(), res.thermal[r][s].end());
    if (!pooled.empty()) out.ljung_box_p[p.nominal.sensors[s].channel] = LjungBoxP(pooled, 10);
  }
  if (!p.has_bias) return out;
  const auto& held = res.bias;
  std::vector<double> pooled;
  for (int r : p.Scored()) pooled.insert(pooled.end(), held[r].data(), held[r].data() + held[r].size());
  out.ljung_box_p["bias_dph"] = LjungBoxP(pooled, 10);
  for (int r : p.Scored()) {
    const auto step = LargestStep(held[r], p.block_times[r], p.runs[r].label);
    if (step && step->statistic > step->threshold) {
      out.detected_steps.push_back(*step);
      out.notes.push_back(StepNote(*step));
    }
  }
  return out;
}

}  // namespace rlg::diagnosis
