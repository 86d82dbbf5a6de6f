#include "validation/plan_result.h"

#include <fmt/format.h>
#include <limits>

#include "validation/order_statistics.h"
#include "validation/population_suite.h"

namespace rlg::validation {

Distribution Summarize(const std::vector<double>& values) {
  Distribution d;
  d.median = Percentile(values, 0.5);
  d.p95 = Percentile(values, 0.95);
  d.worst = -std::numeric_limits<double>::infinity();
  for (size_t i = 0; i < values.size(); ++i) {
    if (values[i] > d.worst) {
      d.worst = values[i];
      d.worst_gyro = i;
    }
  }
  const auto iv = QuantileIntervalValues(values, 0.95, kPlanIntervalLevel);
  d.p95_lo = iv.first;
  d.p95_hi = iv.second;
  return d;
}

std::vector<size_t> ParetoFront(const std::vector<double>& hours, const std::vector<double>& p95) {
  std::vector<size_t> front;
  for (size_t i = 0; i < hours.size(); ++i) {
    bool dominated = false;
    for (size_t j = 0; j < hours.size() && !dominated; ++j) {
      if (j == i) continue;
      dominated = hours[j] <= hours[i] && p95[j] <= p95[i] && (hours[j] < hours[i] || p95[j] < p95[i]);
    }
    if (!dominated) front.push_back(i);
  }
  return front;
}

std::string FormatInterval(const Distribution& d) {
  return fmt::format("[{}, {}]", d.p95_lo ? fmt::format("{:.4f}", *d.p95_lo) : "-inf",
                     d.p95_hi ? fmt::format("{:.4f}", *d.p95_hi) : "inf");
}

const char* MeetsName(Meets meets) {
  switch (meets) {
    case Meets::kYes: return "yes";
    case Meets::kNo: return "no";
    case Meets::kUndecided: return "undecided";
  }
  return "";
}

const char* VerdictName(Verdict verdict) {
  switch (verdict) {
    case Verdict::kConsistent: return "consistent";
    case Verdict::kInconsistent: return "inconsistent";
    case Verdict::kUndecided: return "undecided";
  }
  return "";
}

Verdict VerifyVerdict(std::optional<double> predicted_lo, std::optional<double> predicted_hi,
                      std::optional<double> realised_lo, std::optional<double> realised_hi) {
  const double inf = std::numeric_limits<double>::infinity();
  const double plo = predicted_lo.value_or(-inf), phi = predicted_hi.value_or(inf);
  const double vlo = realised_lo.value_or(-inf), vhi = realised_hi.value_or(inf);
  if (!(plo <= vhi && vlo <= phi)) return Verdict::kInconsistent;
  const bool closed = predicted_lo && predicted_hi && realised_lo && realised_hi;
  return closed ? Verdict::kConsistent : Verdict::kUndecided;
}

}  // namespace rlg::validation
