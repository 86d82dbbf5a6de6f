#include "validation/plan_spec.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fmt/format.h>
#include <fmt/ranges.h>
#include <map>
#include <toml++/toml.h>

#include "io/gyro_file.h"
#include "io/input_file.h"
#include "io/scenario_file.h"
#include "io/toml_reader.h"
#include "validation/fit_request_toml.h"
#include "sim/errors.h"
#include "sim/limits.h"

namespace rlg::validation {

namespace limits = sim::limits;

namespace {

// A chamber holds -70 ... +180 °C at most; the simulator's limits are wider, a plan's are the
// chamber's and the gyro's service range.
constexpr double kMinChamber_C = -70.0, kMaxChamber_C = 180.0;
// A run of up to 10 days: longer is not a calibration run.
constexpr double kMaxDuration_s = 10.0 * 86400.0;
// Up to a week of settling before a run.
constexpr double kMaxSettle_h = 168.0;
// Ramps from 0.001 °C/min (17 h per °C) to 20 °C/min (the fastest chambers).
constexpr double kMinRate = 0.001, kMaxRate = 20.0;
// A plan of 10 million gyros is a cluster's work (docs/plan.md); more is a typing error.
constexpr int64_t kMaxGyros = 10'000'000;

std::string SignedC(double v) { return fmt::format("{}{:g}", v < 0 ? "-" : "+", std::abs(v)); }

// The time (s) a cycle's ambient reaches each of its points after the first, and leaves it
// (after stop_s at an interior point): {arrive, leave} per segment's end.
std::vector<std::pair<double, double>> CycleTimes(const ChamberRun& r) {
  std::vector<std::pair<double, double>> out;
  double t = r.dwell_s;
  for (size_t i = 1; i < r.cycle_C.size(); ++i) {
    t += std::abs(r.cycle_C[i] - r.cycle_C[i - 1]) / r.rate_C_per_min * 60.0;
    const double arrive = t;
    if (i + 1 < r.cycle_C.size()) t += r.stop_s;
    out.emplace_back(arrive, t);
  }
  return out;
}

// Duration of a run from its ramp or cycle when not written.
double DefaultDuration(const ChamberRun& r, double soak_default) {
  if (r.IsCycle()) return CycleTimes(r).back().first + r.hold_s;
  if (r.end_C == r.start_C) return soak_default;
  return r.dwell_s + std::abs(r.end_C - r.start_C) / r.rate_C_per_min * 60.0 + r.hold_s;
}

std::string MadeId(const ChamberRun& r) {
  std::string id;
  if (r.IsCycle()) {
    id = "cycle";
    for (size_t i = 0; i < r.cycle_C.size(); ++i) id += (i > 0 ? "to" : "") + SignedC(r.cycle_C[i]);
  } else {
    id = r.end_C == r.start_C ? "soak" + SignedC(r.start_C) : fmt::format("ramp{}to{}", SignedC(r.start_C), SignedC(r.end_C));
  }
  if (r.power_on_C) id += "-from" + SignedC(*r.power_on_C);
  return id;
}

ChamberRun ReadRun(const io::TomlReader& t, const ChamberDefaults& d, double settle_default, double duration_default,
                   bool service) {
  ChamberRun r;
  r.line = t.line();
  if (service) r.id = t.String("id");
  if (t.Has("cycle_C")) {
    if (t.Has("start_C")) t.Fail("start_C", "a chamber cycle starts at the first point of cycle_C: give one or the other");
    if (t.Has("end_C")) t.Fail("end_C", "a chamber cycle ends at the last point of cycle_C: give one or the other");
    r.cycle_C = t.Numbers("cycle_C");
    bool reverses = false;
    for (size_t i = 0; i < r.cycle_C.size(); ++i) {
      const double T = r.cycle_C[i];
      if (T < kMinChamber_C || T > kMaxChamber_C) {
        t.Fail("cycle_C", fmt::format("{:g} °C is outside the chamber's {:g}...{:g} °C", T, kMinChamber_C, kMaxChamber_C));
      }
      if (i > 0 && T == r.cycle_C[i - 1]) {
        t.Fail("cycle_C", fmt::format("points {} and {} are both {:g} °C: a hold at a point is stop_s", i, i + 1, T));
      }
      if (i > 1 && (T - r.cycle_C[i - 1]) * (r.cycle_C[i - 1] - r.cycle_C[i - 2]) < 0.0) reverses = true;
    }
    if (r.cycle_C.size() < 3 || !reverses) {
      t.Fail("cycle_C", "expected the chamber's points in order, reversing at least once, e.g. [-30, 50, -30] "
                        "(a run that only heats or only cools is a ramp: start_C, end_C)");
    }
    r.start_C = r.cycle_C.front();
    r.end_C = r.cycle_C.back();
    r.rate_C_per_min = t.InRange("rate_C_per_min", kMinRate, kMaxRate);
    r.stop_s = t.InRange("stop_s", 0.0, kMaxDuration_s, 0.0);
  } else {
    r.start_C = t.InRange("start_C", kMinChamber_C, kMaxChamber_C);
    r.end_C = t.InRange("end_C", kMinChamber_C, kMaxChamber_C, r.start_C);
    if (t.Has("stop_s")) t.Fail("stop_s", "stop_s is a chamber cycle's hold at its interior points (cycle_C)");
    if (r.end_C != r.start_C) {
      r.rate_C_per_min = t.InRange("rate_C_per_min", kMinRate, kMaxRate);
    } else if (t.Has("rate_C_per_min")) {
      t.Fail("rate_C_per_min", "a soak (end_C = start_C) has no ramp rate");
    }
  }
  r.dwell_s = t.InRange("dwell_s", 0.0, kMaxDuration_s, 0.0);
  r.hold_s = t.InRange("hold_s", 0.0, kMaxDuration_s, 0.0);
  r.sample_period_s = t.InRange("sample_period_s", limits::kMinSamplePeriod_s, 3600.0, d.sample_period_s);
  if (t.Has("power_on_C")) r.power_on_C = t.InRange("power_on_C", kMinChamber_C, kMaxChamber_C);
  r.settle_h = service ? 0.0 : t.InRange("settle_h", 0.0, kMaxSettle_h, settle_default);
  const double made = DefaultDuration(r, duration_default);
  r.duration_s = t.InRange("duration_s", 0.0, kMaxDuration_s, made);
  if (!(r.duration_s >= 10.0 * r.sample_period_s)) {
    t.Fail("duration_s", fmt::format("expected at least 10 samples of {:g} s", r.sample_period_s));
  }
  if (!service) r.id = MadeId(r);
  return r;
}

model::FitRequest ReadModel(const io::TomlReader& t) {
  model::FitRequest m = ReadFitRequest(t, "name");
  t.Finish();
  return m;
}

ChamberRun Soak(double T, const ChamberDefaults& d) {
  ChamberRun r;
  r.start_C = r.end_C = T;
  r.duration_s = d.duration_s;
  r.sample_period_s = d.sample_period_s;
  r.settle_h = d.settle_h;
  r.id = MadeId(r);
  return r;
}

// A built-in's ramp (two points) or cycle (more): `chamber`'s sampling and settling, its
// duration and id made from its conditions.
ChamberRun Moving(const std::vector<double>& points, double rate, double stop_s, double hold_s, const ChamberDefaults& d) {
  ChamberRun r;
  if (points.size() > 2) r.cycle_C = points;
  r.start_C = points.front();
  r.end_C = points.back();
  r.rate_C_per_min = rate;
  r.stop_s = stop_s;
  r.hold_s = hold_s;
  r.sample_period_s = d.sample_period_s;
  r.settle_h = d.settle_h;
  r.duration_s = DefaultDuration(r, d.duration_s);
  r.id = MadeId(r);
  return r;
}

ChamberRun Ramp(double from, double to, double rate, double hold_s, const ChamberDefaults& d) {
  return Moving({from, to}, rate, 0.0, hold_s, d);
}

}  // namespace

bool ChamberRun::IsValid() const {
  const bool ramp = end_C != start_C || IsCycle();
  bool cycle = true;
  if (IsCycle()) {
    cycle = cycle_C.size() >= 3 && cycle_C.front() == start_C && cycle_C.back() == end_C && stop_s >= 0.0;
    for (size_t i = 0; i < cycle_C.size(); ++i) cycle = cycle && std::isfinite(cycle_C[i]) && (i == 0 || cycle_C[i] != cycle_C[i - 1]);
  }
  return cycle && std::isfinite(start_C) && std::isfinite(end_C) && (!ramp || rate_C_per_min > 0.0) && dwell_s >= 0.0 &&
         hold_s >= 0.0 && duration_s > 0.0 && sample_period_s > 0.0 && settle_h >= 0.0 &&
         duration_s >= 10.0 * sample_period_s;
}

std::string ChamberRun::Conditions() const {
  std::string s = fmt::format("start {:g} °C", start_C);
  if (IsCycle()) {
    s += fmt::format(", after {:g} s a cycle through {:g} °C at {:g} °C/min, {:g} s at each turn", dwell_s,
                     fmt::join(cycle_C, ", "), rate_C_per_min, stop_s);
  } else if (end_C != start_C) {
    s += fmt::format(", after {:g} s ramp at {:g} °C/min to {:g} °C", dwell_s, rate_C_per_min, end_C);
  }
  if (power_on_C) s += fmt::format(", powered on at {:g} °C", *power_on_C);
  s += fmt::format(", {:g} s at {:g} s samples", duration_s, sample_period_s);
  return s;
}

sim::RunSpec ChamberRun::ToRunSpec() const {
  sim::RunSpec spec;
  spec.id = id;
  spec.duration_s = duration_s;
  spec.sample_period_s = sample_period_s;
  if (IsCycle()) {
    // Piecewise linear through the cycle's corners, held at the last point after it.
    std::vector<std::pair<double, double>> points{{0.0, start_C}};
    if (dwell_s > 0.0) points.emplace_back(dwell_s, start_C);
    const auto times = CycleTimes(*this);
    for (size_t i = 0; i < times.size(); ++i) {
      points.emplace_back(times[i].first, cycle_C[i + 1]);
      if (times[i].second > times[i].first) points.emplace_back(times[i].second, cycle_C[i + 1]);
    }
    spec.ambient = sim::Profile::Table(std::move(points));
  } else if (end_C == start_C) {
    spec.ambient = sim::Profile::Constant(start_C);
  } else {
    const double rate = (end_C > start_C ? 1.0 : -1.0) * rate_C_per_min / 60.0;
    spec.ambient = sim::Profile::Ramp(start_C, rate, dwell_s, end_C);
  }
  spec.initial_C = power_on_C;
  spec.line = line;
  return spec;
}

double Candidate::ChamberHours() const {
  double h = 0.0;
  for (const auto& r : runs) h += r.ChamberHours();
  return h;
}

bool PlanSpec::IsValid() const {
  if (gyros < 1 || service.empty() || candidates.empty() || !(target_p95_dph > 0.0) || model.model.empty()) return false;
  if (!(chamber.span_C[0] < chamber.span_C[1])) return false;
  for (const auto& r : service)
    if (!r.IsValid()) return false;
  for (const auto& c : candidates) {
    if (c.runs.empty()) return false;
    for (const auto& r : c.runs)
      if (!r.IsValid()) return false;
  }
  return true;
}

const std::vector<std::string>& BuiltinCandidateNames() {
  static const std::vector<std::string> names{"paper-nine-soaks", "d-optimal-3",    "px4-cold-warm",
                                              "heating-ramp",     "cooling-ramp",   "two-ramps",
                                              "d-optimal-3+ramps", "paper-nine-soaks+ramps", "chamber-cycle"};
  return names;
}

Candidate BuiltinCandidate(const std::string& name, const ChamberDefaults& d) {
  Candidate c;
  c.name = name;
  c.builtin = name;
  const double lo = d.span_C[0], hi = d.span_C[1];
  if (name == "paper-nine-soaks") {
    for (int T = -30; T <= 50; T += 10) c.runs.push_back(Soak(T, d));
  } else if (name == "d-optimal-3") {
    for (double T : {lo, 0.5 * (lo + hi), hi}) c.runs.push_back(Soak(T, d));
  } else if (name == "px4-cold-warm") {
    // PX4's thermal calibration: a cold soak, then a slow warm-up over at least 24 °C.
    c.runs.push_back(Ramp(lo, lo + std::max(hi - lo, 24.0), 0.25, 1800.0, d));
  } else if (name == "heating-ramp") {
    c.runs.push_back(Ramp(lo, hi, d.ramp_C_per_min, 1800.0, d));
  } else if (name == "cooling-ramp") {
    c.runs.push_back(Ramp(hi, lo, d.ramp_C_per_min, 1800.0, d));
  } else if (name == "two-ramps" || name == "d-optimal-3+ramps" || name == "paper-nine-soaks+ramps") {
    // Soaks fix the temperature dependence; a heating and a cooling ramp move the gradients
    // apart from it, which a soak barely does (docs/plan.md, "Service").
    if (name == "d-optimal-3+ramps") c.runs = BuiltinCandidate("d-optimal-3", d).runs;
    if (name == "paper-nine-soaks+ramps") c.runs = BuiltinCandidate("paper-nine-soaks", d).runs;
    c.runs.push_back(Ramp(lo, hi, d.ramp_C_per_min, 1800.0, d));
    c.runs.push_back(Ramp(hi, lo, d.ramp_C_per_min, 1800.0, d));
  } else if (name == "chamber-cycle") {
    // two-ramps' heating and cooling in one power-on: one settling, not two.
    c.runs.push_back(Moving({lo, hi, lo}, d.ramp_C_per_min, 1800.0, 1800.0, d));
  } else {
    throw InputError(fmt::format("unknown candidate '{}': expected one of the built-ins ({}) or a candidate with "
                                 "soaks_C or [[candidates.runs]]",
                                 name, fmt::join(BuiltinCandidateNames(), ", ")));
  }
  return c;
}

namespace {

// The gyro, seed and gyro count (a [population]'s or `gyros`), and the model of the plan.
void ReadGyros(const io::TomlReader& root, PlanSpec& p) {
  const auto dir = std::filesystem::path(p.path).parent_path();
  p.gyro = io::LoadGyro((dir / root.String("gyro")).lexically_normal().string());
  p.seed = static_cast<uint64_t>(root.Integer("seed", 1));
  if (const auto pop = root.OptionalTable("population")) {
    if (root.Has("gyros")) root.Fail("gyros", "a plan with [population] takes its count from [population] count");
    p.population = io::ReadPopulation(*pop);
    p.gyros = p.population->count;
  } else {
    const int64_t n = root.Integer("gyros", 0);
    if (n < 1 || n > kMaxGyros) root.Fail("gyros", fmt::format("expected a gyro count in 1...{}", kMaxGyros));
    p.gyros = static_cast<uint64_t>(n);
  }
  if (const auto m = root.OptionalTable("model")) {
    p.model = ReadModel(*m);
  } else {
    p.model.model = "guo2006";
  }
}

// [target], [screen] and [chamber].
void ReadTargetScreenChamber(const io::TomlReader& root, PlanSpec& p) {
  const auto target = root.OptionalTable("target");
  if (!target) root.FailHere("a plan needs a [target] with p95_abs_bias_after_dph (°/h), e.g. 0.01");
  if (!target->Has("p95_abs_bias_after_dph")) {
    target->FailHere("expected p95_abs_bias_after_dph: the p95 over gyros of |bias after| (°/h) to meet");
  }
  p.target_p95_dph = target->Positive("p95_abs_bias_after_dph");
  target->Finish();
  if (const auto screen = root.OptionalTable("screen")) {
    const int64_t keep = screen->Integer("keep", 0);
    if (keep < 0) screen->Fail("keep", "expected a number of candidates >= 0 (0: simulate all)");
    p.screen_keep = static_cast<size_t>(keep);
    screen->Finish();
  }
  if (const auto ch = root.OptionalTable("chamber")) {
    if (ch->Has("span_C")) {
      const auto s = ch->Numbers("span_C");
      if (s.size() != 2 || !(s[0] < s[1]) || s[0] < kMinChamber_C || s[1] > kMaxChamber_C) {
        ch->Fail("span_C", fmt::format("expected [lo, hi] with {:g} <= lo < hi <= {:g} °C", kMinChamber_C, kMaxChamber_C));
      }
      p.chamber.span_C = {s[0], s[1]};
    }
    p.chamber.settle_h = ch->InRange("settle_h", 0.0, kMaxSettle_h, p.chamber.settle_h);
    p.chamber.ramp_C_per_min = ch->InRange("ramp_C_per_min", kMinRate, kMaxRate, p.chamber.ramp_C_per_min);
    p.chamber.duration_s = ch->InRange("duration_s", 60.0, kMaxDuration_s, p.chamber.duration_s);
    p.chamber.sample_period_s =
        ch->InRange("sample_period_s", limits::kMinSamplePeriod_s, 3600.0, p.chamber.sample_period_s);
    ch->Finish();
  }
}

// The [[service]] runs, ids apart.
void ReadService(const io::TomlReader& root, PlanSpec& p) {
  for (const auto& t : root.ArrayOfTables("service")) {
    ChamberRun r = ReadRun(t, p.chamber, 0.0, p.chamber.duration_s, true);
    for (const auto& other : p.service) {
      if (other.id == r.id) t.Fail("id", fmt::format("a second service run '{}'", r.id));
    }
    t.Finish();
    p.service.push_back(std::move(r));
  }
  if (p.service.empty()) root.FailHere("a plan needs at least one [[service]] run: the conditions to score against");
}

// A candidate's runs: a built-in's, or its own soaks_C and [[candidates.runs]].
void ReadCandidateRuns(const io::TomlReader& t, const ChamberDefaults& chamber, Candidate& c) {
  const bool own = t.Has("soaks_C") || t.Has("runs");
  if (t.Has("builtin") || !own) {
    const std::string b = t.String("builtin", c.name);
    try {
      c.runs = BuiltinCandidate(b, chamber).runs;
    } catch (const InputError& e) {
      t.Fail(t.Has("builtin") ? "builtin" : "name", e.what());
    }
    c.builtin = b;
    if (own) t.FailHere("a built-in candidate takes no soaks_C or runs");
    return;
  }
  const double settle = t.InRange("settle_h", 0.0, kMaxSettle_h, chamber.settle_h);
  const double duration = t.InRange("duration_s", 60.0, kMaxDuration_s, chamber.duration_s);
  ChamberDefaults d = chamber;
  d.settle_h = settle;
  d.duration_s = duration;
  if (t.Has("soaks_C")) {
    for (double T : t.Numbers("soaks_C")) {
      if (T < kMinChamber_C || T > kMaxChamber_C) t.Fail("soaks_C", fmt::format("{:g} °C is outside the chamber's {:g}...{:g} °C", T, kMinChamber_C, kMaxChamber_C));
      ChamberRun r = Soak(T, d);
      r.line = t.line();
      c.runs.push_back(r);
    }
  }
  for (const auto& rt : t.ArrayOfTables("runs")) {
    c.runs.push_back(ReadRun(rt, d, settle, duration, false));
    rt.Finish();
  }
}

// A [[candidates]] entry: its runs and model; no run twice, no second candidate of its name,
// no service run among its runs.
Candidate ReadCandidate(const io::TomlReader& t, const PlanSpec& p) {
  Candidate c;
  c.line = t.line();
  c.name = t.String("name");
  ReadCandidateRuns(t, p.chamber, c);
  if (const auto m = t.OptionalTable("model")) c.model = ReadModel(*m);
  std::map<std::string, int> seen;
  for (const auto& r : c.runs) {
    if (seen.count(r.Conditions())) {
      t.FailHere(fmt::format("candidate '{}' repeats the run '{}' ({}): equal conditions give equal data", c.name,
                             r.id, r.Conditions()));
    }
    seen[r.Conditions()] = r.line;
  }
  for (const auto& other : p.candidates) {
    if (other.name == c.name) t.Fail("name", fmt::format("a second candidate named '{}'", c.name));
  }
  for (const auto& s : p.service) {
    for (const auto& r : c.runs) {
      if (r.Conditions() == s.Conditions()) {
        throw InputError(fmt::format("{}:{}: service run '{}' is also a calibration run of candidate '{}' (line {}: "
                                     "{}): the service conditions must be ones the fit has not seen",
                                     p.path, s.line, s.id, c.name, c.line, s.Conditions()));
      }
    }
  }
  t.Finish();
  return c;
}

}  // namespace

PlanSpec LoadPlan(const std::string& path) {
  if (!io::IsRegularFile(path)) throw InputError(fmt::format("{}: plan file not found", path));
  const auto doc = io::ParseTomlFile(path);
  const io::TomlReader root(*doc, path, "plan", "docs/plan.md");
  PlanSpec p;
  p.path = path;
  ReadGyros(root, p);
  ReadTargetScreenChamber(root, p);
  ReadService(root, p);
  for (const auto& t : root.ArrayOfTables("candidates")) p.candidates.push_back(ReadCandidate(t, p));
  if (p.candidates.empty()) root.FailHere("a plan needs at least one [[candidates]] entry");
  root.Finish();
  return p;
}

}  // namespace rlg::validation
