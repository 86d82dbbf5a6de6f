// Verb plan: calibration protocols predicted before the chamber is booked (validation/plan.h).

#include <CLI/CLI.hpp>
#include <atomic>
#include <cmath>
#include <fmt/format.h>
#include <fstream>
#include <functional>
#include <limits>
#include <memory>
#include <mutex>
#include <nlohmann/json.hpp>
#include <optional>
#include <unistd.h>

#include "tools/rlgtherm/commands.h"
#include "tools/rlgtherm/common.h"
#include "tools/rlgtherm/verb_figures.h"
#include "validation/plan.h"

namespace rlg::cli {
namespace {

// "FROM:TO" -> [FROM, TO) within 0 .. gyros.
std::pair<uint64_t, uint64_t> ParseGyroRange(const std::string& text, uint64_t gyros) {
  const auto colon = text.find(':');
  uint64_t a = 0, b = 0;
  try {
    size_t pa = 0, pb = 0;
    if (colon == std::string::npos) throw std::invalid_argument(text);
    a = std::stoull(text.substr(0, colon), &pa);
    b = std::stoull(text.substr(colon + 1), &pb);
    if (pa != colon || pb != text.size() - colon - 1 || text[0] == '-' || text[colon + 1] == '-') throw std::invalid_argument(text);
  } catch (const std::exception&) {
    throw InputError(fmt::format("--gyros '{}': expected FROM:TO, gyros FROM .. TO-1, e.g. 0:100", text));
  }
  if (!(a < b && b <= gyros)) {
    throw InputError(fmt::format("--gyros {}:{}: expected FROM < TO <= {} (the plan's gyros)", a, b, gyros));
  }
  return {a, b};
}

/// Progress on stderr when it is a terminal (docs/cli.md): the gyros started, counted by the
/// planner's between_gyros hook on whichever thread runs them, one line rewritten in place.
class GyroProgress {
 public:
  GyroProgress(bool tty, uint64_t total) : tty_(tty), total_(total) {}
  ~GyroProgress() {
    if (tty_) fmt::print(stderr, "\r\x1b[K");
  }
  std::function<void()> Hook() {
    if (!tty_) return {};
    return [this] {
      const uint64_t i = ++started_;
      const std::lock_guard<std::mutex> lock(print_);
      fmt::print(stderr, "\rplan: gyro {} of {}\x1b[K", std::min(i, total_), total_);
    };
  }

 private:
  bool tty_;
  uint64_t total_;
  std::atomic<uint64_t> started_{0};
  std::mutex print_;
};

}  // namespace

int RunPlan(const PlanArgs& a) {
  validation::Planner planner(validation::LoadPlan(a.plan));
  const bool tty = ::isatty(STDERR_FILENO);
  if (!a.gyros.empty()) {
    if (!a.merge.empty() || a.verify > 0 || !a.plot.empty()) {
      throw InputError("--gyros FROM:TO simulates one shard: --merge, --verify and --plot belong to the merge");
    }
    const auto [first, end] = ParseGyroRange(a.gyros, planner.spec().gyros);
    GyroProgress progress(tty, end - first);
    const validation::PlanShard shard = planner.Simulate(first, end - first, a.threads, progress.Hook());
    fmt::print("{}\n", validation::ShardJson(planner, shard).dump(2));
    return 0;
  }
  std::optional<FigureDirectory> figures;
  if (!a.plot.empty()) figures.emplace(a.plot);  // an unusable DIR is refused before the work
  validation::PlanResult r;
  if (a.merge.empty()) {
    GyroProgress progress(tty, planner.spec().gyros + a.verify);
    r = planner.Run(a.threads, a.verify, progress.Hook());
  } else {
    std::vector<std::pair<std::string, nlohmann::json>> shards;
    for (const auto& file : a.merge) {
      std::ifstream in(file);
      if (!in) throw InputError(fmt::format("{}: shard file not found", file));
      try {
        shards.emplace_back(file, nlohmann::json::parse(in));
      } catch (const nlohmann::json::parse_error& e) {
        throw InputError(fmt::format("{}: not JSON: {}", file, e.what()));
      }
    }
    GyroProgress progress(tty, a.verify);
    r = planner.Conclude(validation::MergeShards(planner, shards), a.threads, a.verify, progress.Hook());
  }
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
  if (r.verify && r.verify->verdict == validation::Verdict::kInconsistent) return 4;  // undecided is no disagreement
  return 0;
}

Verb RegisterPlan(CLI::App& app) {
  auto a = std::make_shared<PlanArgs>();
  CLI::App* cmd = app.add_subcommand(
      "plan", "predict what calibration protocols leave in service, before the chamber is booked (docs/plan.md)");
  cmd->add_option("PLAN", a->plan, "plan TOML file (docs/plan.md)")->required();
  cmd->add_flag("--json", a->json, "machine-readable output");
  cmd->add_option("--plot", a->plot, "directory for pareto.png: chamber hours against p95 |bias after|");
  cmd->add_option("--threads", a->threads,
                  "gyros in parallel on N threads (default: one per core); the output "
                  "does not depend on N")
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--verify", a->verify,
                  "draw N fresh gyros through the recommended candidate and print the "
                  "realised p95 beside the predicted one");
  cmd->add_option("--gyros", a->gyros,
                  "FROM:TO: simulate gyros FROM .. TO-1 only and print that shard's "
                  "JSON, for --merge (a plan on several machines, docs/plan.md)");
  cmd->add_option("--merge", a->merge,
                  "conclude from the shards of --gyros instead of simulating: the same "
                  "output as the plan run in one piece");
  return {cmd, [a] { return RunPlan(*a); }};
}

}  // namespace rlg::cli
