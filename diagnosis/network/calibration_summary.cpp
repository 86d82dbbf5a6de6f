#include "diagnosis/network/calibration_summary.h"

#include <boost/math/special_functions/gamma.hpp>

#include <cmath>
#include <fmt/format.h>

namespace rlg::diagnosis {

std::vector<std::string> CalibrationSummary::PriorConflicts() const {
  std::vector<std::string> out;
  for (const auto& k : knobs)
    if (std::abs(k.shift_sigma) > kPriorConflictSigma) out.push_back(k.name);
  return out;
}

double CalibrationSummary::JointShiftChi2() const {
  double c = 0.0;
  for (const auto& k : knobs) c += k.shift_sigma * k.shift_sigma;
  return c;
}

double CalibrationSummary::JointShiftP() const {
  if (knobs.empty()) return 1.0;
  return boost::math::gamma_q(0.5 * static_cast<double>(knobs.size()), 0.5 * JointShiftChi2());
}

bool CalibrationSummary::JointConflict() const { return JointShiftP() < kJointConflictP; }

std::string CalibrationSummary::FullReport() const {
  std::string out = fmt::format("calibration: {}, cost {:.6g} -> {:.6g} in {} iterations; prior sd {:.3g} (log units)\n",
                                usable ? "usable" : "NOT usable", initial_cost, final_cost, iterations, prior_sd);
  for (const auto& k : knobs) {
    out += fmt::format("  {:<24} nominal {:<12.6g} calibrated {:<12.6g} shift {:+6.2f} sd{}\n", k.name, k.nominal,
                       k.calibrated, k.shift_sigma, std::abs(k.shift_sigma) > kPriorConflictSigma ? "  prior conflict" : "");
  }
  return out;
}

}  // namespace rlg::diagnosis
