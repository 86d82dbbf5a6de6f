#include "model/pairs.h"

#include <algorithm>
#include <cctype>

namespace rlg::model {

const std::vector<PairCombination>& PaperCombinations() {
  static const std::vector<PairCombination> combos = {
      {"M1", {"T1", "T2"}}, {"M2", {"T1", "T4"}}, {"M3", {"T2", "T4"}},
      {"M4", {"T3", "T2"}}, {"M5", {"T3", "T4"}}, {"M6", {"T4", "T3"}},
  };
  return combos;
}

std::vector<std::string> TemperatureChannels(const sim::Run& run) {
  std::vector<std::string> channels;
  for (const auto& n : run.names) {
    if (n.size() >= 2 && n[0] == 'T' && n != "T_amb" && (std::isdigit(static_cast<unsigned char>(n[1])) || n[1] == '_')) {
      channels.push_back(n);
    }
  }
  return channels;
}

std::vector<std::string> MissingChannels(const sim::Run& run, const std::vector<PairCombination>& combinations) {
  std::vector<std::string> missing;
  for (const auto& combo : combinations)
    for (const auto& ch : combo.pair)
      if (!run.Has(ch) && std::find(missing.begin(), missing.end(), ch) == missing.end()) missing.push_back(ch);
  return missing;
}

std::vector<PairCombination> AllOrderedPairs(const sim::Run& run) {
  const std::vector<std::string> channels = TemperatureChannels(run);
  std::vector<PairCombination> out;
  for (const auto& a : channels) {
    for (const auto& b : channels) {
      if (a == b) continue;
      std::string name = a + "," + b;
      for (const auto& m : PaperCombinations())
        if (m.pair[0] == a && m.pair[1] == b) name = m.name;
      out.push_back({name, {a, b}});
    }
  }
  return out;
}

std::vector<PairScore> ScorePairs(const std::vector<const sim::Run*>& runs,
                                  const std::vector<PairCombination>& combinations, FitOptions options) {
  std::vector<PairScore> scores;
  for (const auto& combo : combinations) {
    options.pair = combo.pair;
    PairScore s;
    s.combination = combo;
    s.coefficients = FitGuo2006(runs, options);
    for (const sim::Run* r : runs) {
      s.per_run.emplace_back(r->id, RunSse(s.coefficients, *r));
      s.sse_ave += s.per_run.back().second;
    }
    s.sse_ave /= static_cast<double>(runs.size());
    scores.push_back(std::move(s));
  }
  return scores;
}

const PairScore& BestPair(const std::vector<PairScore>& scores) {
  return *std::min_element(scores.begin(), scores.end(),
                           [](const PairScore& a, const PairScore& b) { return a.sse_ave < b.sse_ave; });
}

}  // namespace rlg::model
