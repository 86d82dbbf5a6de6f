#include "diagnosis/network/model_residuals.h"

namespace rlg::diagnosis {

ModelResiduals ResidualsOf(const Problem& p, const Model& m, const std::vector<Extra>& extra) {
  const std::vector<int> all = p.All();
  ModelResiduals out;
  out.prediction = SimulateAll(p, m, all);
  out.thermal = ThermalResiduals(p, out.prediction, all);
  if (p.has_bias) out.bias = HeldOutBias(p, Design(p, m, out.prediction, extra));
  return out;
}

}  // namespace rlg::diagnosis
