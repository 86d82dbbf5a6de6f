// Verb plan: calibration protocols predicted before the chamber is booked (validation/plan.h).

#include <cmath>
#include <fmt/format.h>
#include <limits>
#include <nlohmann/json.hpp>
#include <optional>

#include "tools/rlgtherm/commands.h"
#include "tools/rlgtherm/common.h"
#include "tools/rlgtherm/verb_figures.h"
#include "validation/plan.h"

namespace rlg::cli {

int RunPlan(const PlanArgs& a) {
  validation::Planner planner(validation::LoadPlan(a.plan));
  std::optional<FigureDirectory> figures;
  if (!a.plot.empty()) figures.emplace(a.plot);  // an unusable DIR is refused before the work
  const validation::PlanResult r = planner.Run(a.threads, a.verify);
  if (figures) {
    std::vector<FigureDirectory::PlanPoint> points;
    for (size_t c = 0; c < r.candidates.size(); ++c) {
      const auto& cr = r.candidates[c];
      if (!cr.has_numbers()) continue;
      FigureDirectory::PlanPoint p;
      p.name = cr.name;
      p.chamber_h = cr.chamber_h;
      p.p95 = cr.abs_bias_after.p95;
      p.lo = cr.abs_bias_after.p95_lo.value_or(0.0);
      p.hi = cr.abs_bias_after.p95_hi.value_or(std::numeric_limits<double>::infinity());
      p.pareto = cr.pareto;
      p.recommended = r.recommended && *r.recommended == c;
      points.push_back(p);
    }
    figures->WritePareto(points, planner.spec().target_p95_dph,
                         fmt::format("{}: {} gyros, worst service run per gyro", a.plan, planner.spec().gyros));
    figures->Commit();
  }
  if (a.json) {
    fmt::print("{}\n", validation::PlanJson(planner, r).dump(2));
  } else {
    fmt::print("{}", validation::PlanText(planner, r));
  }
  if (!r.recommended) return 4;
  if (r.verify && !r.verify->consistent) return 4;
  return 0;
}

}  // namespace rlg::cli
