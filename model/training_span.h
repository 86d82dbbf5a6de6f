#pragma once
/// The span of a temperature channel over a polynomial fit's training data: the range the model
/// is fitted on (lo ... hi, °C), the runs' median sample period dt (s) and the longest run (s),
/// which set the library's time constants and the reference temperature.

#include <algorithm>
#include <cstddef>
#include <limits>
#include <string>
#include <vector>

#include "model/allan.h"
#include "sim/trace.h"

namespace rlg::model {

struct TrainingSpan {
  double lo = std::numeric_limits<double>::infinity();  ///< °C; lo > hi when no sample counted
  double hi = -std::numeric_limits<double>::infinity();
  double dt = 0.0;       ///< s, the median over runs of 2+ samples of their sample period; 0 when none has 2
  double longest = 0.0;  ///< s, the longest run's duration
};

/// The span of `channel` over the samples for which `used(r, k)` holds (sample k of runs[r]);
/// dt and longest count every run. Each run must hold the channel (Run::Column's error if not).
template <class Used>
TrainingSpan SpanOf(const std::vector<const sim::Run*>& runs, const std::string& channel, Used used) {
  TrainingSpan span;
  std::vector<double> periods;
  for (size_t r = 0; r < runs.size(); ++r) {
    const auto& T = runs[r]->Column(channel);
    for (size_t k = 0; k < T.size(); ++k) {
      if (!used(r, k)) continue;
      span.lo = std::min(span.lo, T[k]);
      span.hi = std::max(span.hi, T[k]);
    }
    if (runs[r]->size() >= 2) {
      periods.push_back(SamplePeriod(runs[r]->t_s));
      span.longest = std::max(span.longest, runs[r]->t_s.back() - runs[r]->t_s.front());
    }
  }
  if (!periods.empty()) {
    std::nth_element(periods.begin(), periods.begin() + static_cast<std::ptrdiff_t>(periods.size() / 2), periods.end());
    span.dt = periods[periods.size() / 2];
  }
  return span;
}

}  // namespace rlg::model
