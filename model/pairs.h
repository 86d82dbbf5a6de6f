#pragma once
/// Choosing the sensor pair (the paper's Table 1): fit Eq. (2) for each combination and score
/// it by Eq. (3),
///   SSE_ave = (1/m) sum_{j=1..m} sum_{i=1..n_j} (y_i - yhat_i)²,
/// y the measured bias, yhat = B0 + model, m the runs (test temperatures), n_j their samples.

#include <array>
#include <map>
#include <string>
#include <vector>

#include "model/guo2006.h"
#include "sim/trace.h"

namespace rlg::model {

struct PairCombination {
  std::string name;                  ///< "M1" ... "M6", or "T3,T1" for any other ordered pair
  std::array<std::string, 2> pair;   ///< (Pi, Pj): Ti is the main temperature
};

/// The paper's six, in its order: M1 (P1,P2), M2 (P1,P4), M3 (P2,P4), M4 (P3,P2), M5 (P3,P4), M6 (P4,P3).
const std::vector<PairCombination>& PaperCombinations();
/// The temperature channels T1, T2, ..., T_name present in `run`, in file order (not T_amb).
std::vector<std::string> TemperatureChannels(const sim::Run& run);
/// Every ordered pair of TemperatureChannels(run).
std::vector<PairCombination> AllOrderedPairs(const sim::Run& run);
/// The channels that `combinations` use and `run` lacks, in the order first used.
std::vector<std::string> MissingChannels(const sim::Run& run, const std::vector<PairCombination>& combinations);

struct PairScore {
  PairCombination combination;
  std::vector<std::pair<std::string, double>> per_run;  ///< (run id, SSE), in run order
  double sse_ave = 0.0;
  Guo2006Coefficients coefficients;
};

/// Fits each combination on all `runs` and scores it; result in the order given. The best
/// is the one with the smallest sse_ave (BestPair).
std::vector<PairScore> ScorePairs(const std::vector<const sim::Run*>& runs,
                                  const std::vector<PairCombination>& combinations, FitOptions options);
const PairScore& BestPair(const std::vector<PairScore>& scores);

}  // namespace rlg::model
