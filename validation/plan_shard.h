#pragma once
/// A plan on machines apart (`plan --gyros FROM:TO --json`, `plan --merge SHARD.json..`,
/// docs/plan.md): a shard holds the outcomes of a range of the plan's gyros; the shards of one
/// plan merged give the outcomes of every gyro, and Planner::Conclude on them the bytes of the
/// plan run in one piece.

#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "validation/plan_planner.h"

namespace rlg::validation {

/// A shard for machines apart (`plan --gyros FROM:TO --json`, docs/plan.md): the plan file's
/// digest (FNV-1a of its bytes) and seed, the gyro range, and per simulated candidate each gyro's
/// score, stability, |bias after| per service run and fit failure; doubles as JSON writes them
/// (shortest round trip), so a merge reads back the same bits.
nlohmann::json ShardJson(const Planner& planner, const PlanShard& shard);
/// The shards of one plan merged (`plan --merge SHARD.json..`): InputError naming the file for a
/// shard of another plan file or seed, a gyro in two shards or in none, or a malformed shard.
/// Conclude on the result gives the bytes of the plan run in one piece.
PlanShard MergeShards(const Planner& planner, const std::vector<std::pair<std::string, nlohmann::json>>& shards);

}  // namespace rlg::validation
