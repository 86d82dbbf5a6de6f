#include "diagnosis/network/knob_prior.h"

#include <cmath>

#include "diagnosis/network/calibration_summary.h"

namespace rlg::diagnosis {

double KnobShiftSigma(const Problem& p, const Model& m, size_t i) {
  return std::log(m.base[i] / p.knobs[i].nominal) / p.nominal.calibration_uncertainty;
}

double KnobPriorCost(const Problem& p, const Model& m) {
  double c = 0.0;
  for (size_t i = 0; i < p.knobs.size(); ++i) c += std::pow(KnobShiftSigma(p, m, i), 2);
  return c;
}

bool KnobsInConflict(const Problem& p, const Model& m) {
  CalibrationSummary c;
  for (size_t i = 0; i < p.knobs.size(); ++i)
    c.knobs.push_back({p.knobs[i].name, p.knobs[i].nominal, m.base[i], KnobShiftSigma(p, m, i), 0.0, p.knobs[i].Label()});
  return !c.PriorConflicts().empty();
}

}  // namespace rlg::diagnosis
