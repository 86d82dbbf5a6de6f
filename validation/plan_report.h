#pragma once
/// The plan's reports (docs/plan.md): `plan --json`, the text (a table of the candidates, their
/// p95 |bias after| per service run, the verification) and the one-line answer both end with.

#include <string>

#include <nlohmann/json_fwd.hpp>

#include "validation/plan_planner.h"
#include "validation/plan_result.h"

namespace rlg::validation {

/// `plan --json` (docs/plan.md) and the text report: a table, then a one-line answer.
nlohmann::json PlanJson(const Planner& planner, const PlanResult& r);
std::string PlanText(const Planner& planner, const PlanResult& r);
/// The one-line answer both end with: "answer: NAME (H chamber h): p95 ... REASON" or
/// "answer: none: REASON".
std::string PlanAnswer(const PlanResult& r);

}  // namespace rlg::validation
