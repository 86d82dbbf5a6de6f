#include "validation/plan_shard.h"

#include <fmt/format.h>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "sim/errors.h"

namespace rlg::validation {

namespace {

// The digest a shard names its plan file by: FNV-1a of the file's bytes.
uint64_t PlanDigest(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(fmt::format("{}: plan file not found", path));
  std::ostringstream text;
  text << in.rdbuf();
  return Fnv1a(text.str());
}

}  // namespace

nlohmann::json ShardJson(const Planner& planner, const PlanShard& sh) {
  const PlanSpec& spec = planner.spec();
  nlohmann::json j;
  j["plan_shard"] = {{"plan", spec.path},
                     {"digest", fmt::format("{:016x}", PlanDigest(spec.path))},
                     {"seed", spec.seed},
                     {"gyros", {sh.first, sh.first + sh.count}}};
  j["candidates"] = nlohmann::json::array();
  for (size_t k = 0; k < sh.kept.size(); ++k) {
    nlohmann::json c;
    c["name"] = spec.candidates[sh.kept[k]].name;
    nlohmann::json score = nlohmann::json::array(), stab = nlohmann::json::array(), service = nlohmann::json::array(),
                   failure = nlohmann::json::array();
    for (const auto& o : sh.outcomes[k]) {
      score.push_back(o.score);
      stab.push_back(o.stability);
      service.push_back(o.service_abs_bias);
      failure.push_back(o.failure);
    }
    c["score_dph"] = score;
    c["stability_100s_dph"] = stab;
    c["service_abs_bias_dph"] = service;
    c["failure"] = failure;
    j["candidates"].push_back(c);
  }
  return j;
}

PlanShard MergeShards(const Planner& planner, const std::vector<std::pair<std::string, nlohmann::json>>& shards) {
  const PlanSpec& spec = planner.spec();
  const std::string digest = fmt::format("{:016x}", PlanDigest(spec.path));
  PlanShard all = planner.Simulate(0, 0, 1);  // the screen and its choice, no gyro
  all.count = spec.gyros;
  all.outcomes.assign(all.kept.size(), std::vector<GyroCandidateOutcome>(spec.gyros));
  std::vector<std::string> from(spec.gyros);  // the shard that gave each gyro
  for (const auto& [file, j] : shards) {
    try {
      const auto& h = j.at("plan_shard");
      if (h.at("digest").get<std::string>() != digest || h.at("seed").get<uint64_t>() != spec.seed) {
        throw InputError(fmt::format("{}: a shard of another plan file or seed than {} (seed {})", file, spec.path, spec.seed));
      }
      const uint64_t a = h.at("gyros").at(0).get<uint64_t>(), b = h.at("gyros").at(1).get<uint64_t>();
      if (!(a <= b && b <= spec.gyros)) {
        throw InputError(fmt::format("{}: gyros {}..{} are not all in a plan of {}", file, a, b, spec.gyros));
      }
      const auto& cands = j.at("candidates");
      if (cands.size() != all.kept.size()) {
        throw InputError(fmt::format("{}: {} candidates simulated, the plan's screen keeps {}", file, cands.size(), all.kept.size()));
      }
      for (size_t k = 0; k < all.kept.size(); ++k) {
        const auto& c = cands.at(k);
        if (c.at("name").get<std::string>() != spec.candidates[all.kept[k]].name) {
          throw InputError(fmt::format("{}: candidate {} is '{}', the plan's is '{}'", file, k + 1,
                                       c.at("name").get<std::string>(), spec.candidates[all.kept[k]].name));
        }
        if (c.at("score_dph").size() != b - a || c.at("stability_100s_dph").size() != b - a ||
            c.at("service_abs_bias_dph").size() != b - a || c.at("failure").size() != b - a) {
          throw InputError(fmt::format("{}: candidate '{}' has not one value per gyro of {}..{}", file,
                                       spec.candidates[all.kept[k]].name, a, b));
        }
        for (uint64_t i = a; i < b; ++i) {
          GyroCandidateOutcome& o = all.outcomes[k][i];
          o.score = c["score_dph"][i - a].get<double>();
          o.stability = c["stability_100s_dph"][i - a].get<double>();
          o.service_abs_bias = c["service_abs_bias_dph"][i - a].get<std::vector<double>>();
          o.failure = c["failure"][i - a].get<std::string>();
        }
      }
      for (uint64_t i = a; i < b; ++i) {
        if (!from[i].empty()) throw InputError(fmt::format("{}: gyro {} is also in {}", file, i, from[i]));
        from[i] = file;
      }
    } catch (const nlohmann::json::exception& e) {
      throw InputError(fmt::format("{}: not a plan shard of `plan --gyros FROM:TO --json` ({})", file, e.what()));
    }
  }
  for (uint64_t i = 0; i < spec.gyros; ++i) {
    if (from[i].empty()) throw InputError(fmt::format("{}: no shard holds gyro {} (of 0..{})", spec.path, i, spec.gyros - 1));
  }
  return all;
}

}  // namespace rlg::validation
