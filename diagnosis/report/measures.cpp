// The report's measures of a diagnosis (report.h): plausibility, what is left, the headline gains.

#include "diagnosis/report.h"

#include <cmath>
#include <fmt/format.h>
#include <fmt/ranges.h>
#include <limits>

#include "diagnosis/catalog/effect_search.h"

namespace rlg::diagnosis {

std::vector<sim::RangeViolation> OutsidePlausibleRange(const Candidate& c) {
  const EffectSearch* effect = FindSearch(c.cause);
  return effect ? effect->OutsidePlausibleRange(c.parameters) : std::vector<sim::RangeViolation>{};
}

std::string StandInText(const Candidate& c) {
  const auto outside = OutsidePlausibleRange(c);
  if (outside.empty()) return "";
  std::vector<std::string> what;
  for (const auto& v : outside) {
    what.push_back(fmt::format("{} = {:.4g} {} (plausible {:.3g} to {:.3g}: {})", v.parameter->name, v.value,
                               v.parameter->unit, v.parameter->lo, v.parameter->hi, v.parameter->source));
  }
  return fmt::format("{} was fitted at an implausible size, {}: the data do not bound it there, or the catalog's cause "
                     "stands in for something it does not hold",
                     c.cause, fmt::join(what, ", "));
}

double BiasLeft::RmsOverNoise() const {
  if (noise_dph > 0.0) return rms_dph / noise_dph;
  return rms_dph > 0.0 ? std::numeric_limits<double>::infinity() : 0.0;
}

bool LeftAtNoise(const BiasLeft& l) { return !(l.RmsOverNoise() > kAllClearRmsOverNoise); }

std::string LeftText(const BiasLeft& l, const std::string& score_block) {
  const double ratio = l.RmsOverNoise();
  return fmt::format("the held-out residual is {:.3g} °/h RMS on {} means, {} the white noise of such a mean ({:.2g} °/h)",
                     l.rms_dph, score_block, std::isfinite(ratio) ? fmt::format("{:.1f}x", ratio) : std::string("beyond"),
                     l.noise_dph);
}

double HeadlineRmsRatio(const SearchRecord& d) {
  if (d.steps.empty()) return 1.0;
  const Candidate& first = d.steps.front().accepted;
  if (d.has_bias && d.extended.bias_rms_dph > 0.0 && first.kind == CandidateKind::kBias) {
    return d.baseline.bias_rms_dph / d.extended.bias_rms_dph;
  }
  return first.heldout_rms_ratio;
}

double CompensatedStabilityRatio(const SearchRecord& d) {
  double stability = 1.0;
  for (const auto& s : d.steps) stability *= s.compensated_stability_ratio;
  return stability;
}

}  // namespace rlg::diagnosis
