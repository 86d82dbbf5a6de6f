#include "validation/plan_report.h"

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <nlohmann/json.hpp>
#include <vector>

namespace rlg::validation {

namespace {

nlohmann::json OptionalNumber(const std::optional<double>& v) { return v ? nlohmann::json(*v) : nlohmann::json(nullptr); }

// A candidate of `plan --json`: its runs, screen, and its numbers (null when it has none).
nlohmann::json CandidateJson(const PlanSpec& spec, const Candidate& cand, const CandidateResult& cr) {
  nlohmann::json x;
  x["name"] = cr.name;
  x["builtin"] = cand.builtin.empty() ? nlohmann::json(nullptr) : nlohmann::json(cand.builtin);
  x["model"] = cr.model;
  x["chamber_h"] = cr.chamber_h;
  x["runs"] = nlohmann::json::array();
  for (const auto& run : cand.runs) {
    x["runs"].push_back({{"id", run.id}, {"conditions", run.Conditions()}, {"chamber_h", run.ChamberHours()}});
  }
  nlohmann::json sc;
  if (cr.screen.failure.empty()) {
    sc["median_abs_bias_after_dph"] = cr.screen.median_dph;
    sc["p95_abs_bias_after_dph"] = cr.screen.p95_dph;
    sc["service"] = nlohmann::json::array();
    for (size_t s = 0; s < spec.service.size(); ++s) {
      sc["service"].push_back({{"id", spec.service[s].id}, {"bias_dph", cr.screen.bias_dph[s]}, {"sd_dph", cr.screen.sd_dph[s]}});
    }
    sc["failure"] = nullptr;
  } else {
    sc["failure"] = cr.screen.failure;
  }
  sc["mc_to_screen_p95"] = cr.has_numbers() && cr.screen.p95_dph > 0
                               ? nlohmann::json(cr.abs_bias_after.p95 / cr.screen.p95_dph)
                               : nlohmann::json(nullptr);
  x["screen"] = sc;
  x["simulated"] = cr.simulated;
  x["failure"] = cr.failure.empty() ? (cr.screen.failure.empty() ? nlohmann::json(nullptr) : nlohmann::json(cr.screen.failure))
                                    : nlohmann::json(cr.failure);
  if (cr.has_numbers()) {
    const auto& d = cr.abs_bias_after;
    x["median_abs_bias_after_dph"] = d.median;
    x["p95_abs_bias_after_dph"] = d.p95;
    x["p95_interval_dph"] = {OptionalNumber(d.p95_lo), OptionalNumber(d.p95_hi)};
    x["worst_abs_bias_after_dph"] = d.worst;
    x["worst_gyro"] = d.worst_gyro;
    x["median_stability_100s_after_dph"] = cr.stability_100s.median;
    x["p95_stability_100s_after_dph"] = cr.stability_100s.p95;
    x["service"] = nlohmann::json::array();
    for (size_t s = 0; s < spec.service.size(); ++s) {
      x["service"].push_back({{"id", spec.service[s].id},
                              {"median_abs_bias_after_dph", cr.service[s].median},
                              {"p95_abs_bias_after_dph", cr.service[s].p95},
                              {"p95_interval_dph", {OptionalNumber(cr.service[s].p95_lo), OptionalNumber(cr.service[s].p95_hi)}}});
    }
    x["meets_target"] = cr.meets ? MeetsName(*cr.meets) : "";
  } else {
    for (const char* k : {"median_abs_bias_after_dph", "p95_abs_bias_after_dph", "p95_interval_dph",
                          "worst_abs_bias_after_dph", "worst_gyro", "median_stability_100s_after_dph",
                          "p95_stability_100s_after_dph", "service", "meets_target"}) {
      x[k] = nullptr;
    }
  }
  x["pareto"] = cr.pareto;
  return x;
}

// The verification of `plan --json`: the recommended candidate's predicted p95 beside the
// realised one.
nlohmann::json VerifyJson(const PlanResult& r) {
  const auto& v = *r.verify;
  const auto& p = r.candidates[*r.recommended].abs_bias_after;
  return {{"candidate", r.candidates[*r.recommended].name},
          {"gyros", v.gyros},
          {"seed", v.seed},
          {"predicted_p95_dph", p.p95},
          {"predicted_interval_dph", {OptionalNumber(p.p95_lo), OptionalNumber(p.p95_hi)}},
          {"realised_p95_dph", v.realised_p95},
          {"realised_interval_dph", {OptionalNumber(v.realised_lo), OptionalNumber(v.realised_hi)}},
          {"consistent", v.consistent()},
          {"verdict", VerdictName(v.verdict)},
          {"gyros_needed", v.gyros_needed}};
}

// The text's verdict of the verification, with what decides an undecided one.
std::string VerdictText(const VerifyResult& v) {
  switch (v.verdict) {
    case Verdict::kConsistent: return "consistent (the intervals overlap)";
    case Verdict::kInconsistent: return "INCONSISTENT (the intervals do not overlap)";
    case Verdict::kUndecided: break;
  }
  return fmt::format("undecided (an interval open at one end overlaps almost anything: {} gyros bound the p95's 90 % "
                     "interval on both sides; --verify {} or more decides)",
                     v.gyros_needed, v.gyros_needed);
}

}  // namespace

nlohmann::json PlanJson(const Planner& planner, const PlanResult& r) {
  const PlanSpec& spec = planner.spec();
  nlohmann::json j;
  j["plan"] = spec.path;
  j["gyros"] = spec.gyros;
  j["seed"] = spec.seed;
  j["population"] = spec.population.has_value();
  j["model"] = spec.model.model;
  j["target"] = {{"p95_abs_bias_after_dph", spec.target_p95_dph}};
  j["interval_level"] = kPlanIntervalLevel;
  j["service"] = nlohmann::json::array();
  for (const auto& s : spec.service) j["service"].push_back({{"id", s.id}, {"conditions", s.Conditions()}});
  j["candidates"] = nlohmann::json::array();
  for (size_t c = 0; c < r.candidates.size(); ++c) {
    j["candidates"].push_back(CandidateJson(spec, spec.candidates[c], r.candidates[c]));
  }
  j["pareto"] = nlohmann::json::array();
  for (const auto& cr : r.candidates)
    if (cr.pareto) j["pareto"].push_back(cr.name);
  j["recommended"] = r.recommended ? nlohmann::json(r.candidates[*r.recommended].name) : nlohmann::json(nullptr);
  j["reason"] = r.reason;
  j["answer"] = PlanAnswer(r);
  if (r.verify) j["verify"] = VerifyJson(r);
  return j;
}

std::string PlanText(const Planner& planner, const PlanResult& r) {
  const PlanSpec& spec = planner.spec();
  std::string s;
  s += fmt::format("Plan {}: {} gyros{}, model {}, target p95 |bias after| <= {:g} °/h over {} service runs ({})\n",
                   spec.path, spec.gyros, spec.population ? " (population)" : " (the nominal gyro, noise only)",
                   spec.model.model, spec.target_p95_dph, spec.service.size(), [&] {
                     std::vector<std::string> ids;
                     for (const auto& x : spec.service) ids.push_back(x.id);
                     return fmt::format("{}", fmt::join(ids, ", "));
                   }());
  s += "|bias after| of a gyro: its worst service run; intervals: 90 %, distribution-free; °/h\n\n";
  s += fmt::format("{:<22} {:>7} {:>8} {:>19} {:>8} {:>8} {:>8} {:>8} {:>6} {:<9} {}\n", "candidate", "chamber",
                   "p95", "p95 interval", "median", "worst", "stab100", "screen", "MC/scr", "meets", "");
  s += fmt::format("{:<22} {:>7} {:>8} {:>19} {:>8} {:>8} {:>8} {:>8} {:>6} {:<9} {}\n", "", "h", "", "", "", "",
                   "p95", "p95", "", "target", "");
  std::vector<std::string> notes;
  for (const auto& cr : r.candidates) {
    const std::string screen = cr.screen.failure.empty() ? fmt::format("{:.4f}", cr.screen.p95_dph) : "-";
    if (cr.has_numbers()) {
      const auto& d = cr.abs_bias_after;
      s += fmt::format("{:<22} {:>7.1f} {:>8.4f} {:>19} {:>8.4f} {:>8.4f} {:>8.4f} {:>8} {:>6.2f} {:<9} {}\n", cr.name,
                       cr.chamber_h, d.p95, FormatInterval(d), d.median, d.worst, cr.stability_100s.p95, screen,
                       cr.screen.p95_dph > 0 ? d.p95 / cr.screen.p95_dph : 0.0, cr.meets ? MeetsName(*cr.meets) : "", cr.pareto ? "pareto" : "");
    } else {
      const std::string why = !cr.screen.failure.empty() ? "cannot be fitted" : cr.simulated ? "fit failed" : "screened out";
      s += fmt::format("{:<22} {:>7.1f} {:>8} {:>19} {:>8} {:>8} {:>8} {:>8} {:>6} {:<9}\n", cr.name, cr.chamber_h, "-",
                       why, "-", "-", "-", screen, "-", "-");
      if (!cr.screen.failure.empty()) notes.push_back(fmt::format("{}: {}", cr.name, cr.screen.failure));
      if (!cr.failure.empty()) notes.push_back(fmt::format("{}: {}", cr.name, cr.failure));
    }
  }
  s += "\np95 |bias after| per service run, °/h\n";
  s += fmt::format("{:<22}", "candidate");
  for (const auto& x : spec.service) s += fmt::format(" {:>14}", x.id);
  s += "\n";
  for (const auto& cr : r.candidates) {
    if (!cr.has_numbers()) continue;
    s += fmt::format("{:<22}", cr.name);
    for (const auto& d : cr.service) s += fmt::format(" {:>14.4f}", d.p95);
    s += "\n";
  }
  for (const auto& n : notes) s += "  " + n + "\n";
  if (r.verify) {
    const auto& v = *r.verify;
    const auto& p = r.candidates[*r.recommended].abs_bias_after;
    Distribution realised;
    realised.p95_lo = v.realised_lo;
    realised.p95_hi = v.realised_hi;
    s += fmt::format("\nverify: {} fresh gyros through {}: realised p95 {:.4f} {} against predicted {:.4f} {}: {}\n",
                     v.gyros, r.candidates[*r.recommended].name, v.realised_p95, FormatInterval(realised), p.p95,
                     FormatInterval(p), VerdictText(v));
  }
  s += "\n" + PlanAnswer(r) + "\n";
  return s;
}

std::string PlanAnswer(const PlanResult& r) {
  if (!r.recommended) return fmt::format("answer: none: {}", r.reason);
  const auto& b = r.candidates[*r.recommended];
  return fmt::format("answer: {} ({:.1f} chamber h): p95 |bias after| {:.4f} °/h {}, {}", b.name, b.chamber_h,
                     b.abs_bias_after.p95, FormatInterval(b.abs_bias_after), r.reason);
}

}  // namespace rlg::validation
