#include "validation/plan.h"

#include <algorithm>
#include <cmath>
#include <fmt/format.h>
#include <fmt/ranges.h>
#include <limits>
#include <fstream>
#include <map>
#include <sstream>
#include <nlohmann/json.hpp>

#include "compensation/model_compensator.h"
#include "model/allan.h"
#include "sim/errors.h"
#include "sim/simulator.h"
#include "validation/order_statistics.h"
#include "validation/parallel.h"
#include "validation/plan_screen.h"
#include "validation/population_suite.h"

namespace rlg::validation {

namespace {

// FNV-1a, 64 bit: a run's stream from its conditions.
uint64_t Fnv1a(const std::string& s) {
  uint64_t h = 14695981039346656037ull;
  for (unsigned char c : s) {
    h ^= c;
    h *= 1099511628211ull;
  }
  return h;
}

// Calibration and service runs on streams apart (a service run is never a calibration run, but
// the two must not share noise even so), and apart from the population's parameter stream.
uint64_t CalibrationStream(const ChamberRun& r) { return Fnv1a("calibration: " + r.Conditions()); }
uint64_t ServiceStream(const ChamberRun& r) { return Fnv1a("service: " + r.Conditions()); }

sim::GyroConfig NoiseFree(sim::GyroConfig g) {
  g.noise = sim::GyroNoiseParams{};
  for (auto& s : g.sensors) s.noise = sim::SensorNoiseParams{};
  return g;
}

struct RunMetrics {
  double mean = 0.0, stability_100s = 0.0;
};

RunMetrics Score(const model::FittedModel& m, const sim::Run& run) {
  const std::vector<double> c = compensation::CompensateRun(m, run);
  RunMetrics out;
  double sum = 0.0;
  for (double v : c) sum += v;
  out.mean = sum / static_cast<double>(c.size());
  out.stability_100s =
      model::BiasStability(c, run.MeanSamplePeriod(), 100.0, model::BelowSamplePeriod::kUseOneSample).sigma;
  return out;
}

// The regressor rows of a run, as the fit stacks them (referred to the B0 window where the
// model is).
Eigen::MatrixXd Rows(const model::CausalRegressors& proto, const sim::Run& run) {
  auto g = proto.Clone();
  g->Reset();
  const auto& ch = g->channels();
  std::vector<const std::vector<double>*> cols;
  for (const auto& c : ch) cols.push_back(&run.Column(c));
  const Eigen::Index p = static_cast<Eigen::Index>(g->names().size());
  Eigen::MatrixXd X(static_cast<Eigen::Index>(run.size()), p);
  std::vector<double> T(ch.size()), row(static_cast<size_t>(p));
  for (size_t k = 0; k < run.size(); ++k) {
    for (size_t j = 0; j < ch.size(); ++j) T[j] = (*cols[j])[k];
    g->Next(run.t_s[k], T.data(), row.data());
    for (Eigen::Index j = 0; j < p; ++j) X(static_cast<Eigen::Index>(k), j) = row[static_cast<size_t>(j)];
  }
  if (g->ReferredToB0Window()) {
    Eigen::Index n0 = 0;
    while (n0 < X.rows() && run.t_s[static_cast<size_t>(n0)] - run.t_s[0] < g->b0_window_s()) ++n0;
    n0 = std::max<Eigen::Index>(n0, 1);
    const Eigen::RowVectorXd G0 = X.topRows(n0).colwise().mean();
    X.rowwise() -= G0;
  }
  return X;
}

double B0Samples(const model::CausalRegressors& g, const sim::Run& run) {
  if (g.offset() != model::OffsetRule::kPowerOn) return 0.0;
  size_t n0 = 0;
  while (n0 < run.size() && run.t_s[n0] - run.t_s[0] < g.b0_window_s()) ++n0;
  return static_cast<double>(std::max<size_t>(n0, 1));
}

nlohmann::json OptionalNumber(const std::optional<double>& v) { return v ? nlohmann::json(*v) : nlohmann::json(nullptr); }

std::string FormatInterval(const Distribution& d) {
  return fmt::format("[{}, {}]", d.p95_lo ? fmt::format("{:.4f}", *d.p95_lo) : "-inf",
                     d.p95_hi ? fmt::format("{:.4f}", *d.p95_hi) : "inf");
}

}  // namespace

Distribution Summarize(const std::vector<double>& values) {
  Distribution d;
  d.median = Percentile(values, 0.5);
  d.p95 = Percentile(values, 0.95);
  d.worst = -std::numeric_limits<double>::infinity();
  for (size_t i = 0; i < values.size(); ++i) {
    if (values[i] > d.worst) {
      d.worst = values[i];
      d.worst_gyro = i;
    }
  }
  const auto iv = QuantileIntervalValues(values, 0.95, kPlanIntervalLevel);
  d.p95_lo = iv.first;
  d.p95_hi = iv.second;
  return d;
}

std::vector<size_t> ParetoFront(const std::vector<double>& hours, const std::vector<double>& p95) {
  std::vector<size_t> front;
  for (size_t i = 0; i < hours.size(); ++i) {
    bool dominated = false;
    for (size_t j = 0; j < hours.size() && !dominated; ++j) {
      if (j == i) continue;
      dominated = hours[j] <= hours[i] && p95[j] <= p95[i] && (hours[j] < hours[i] || p95[j] < p95[i]);
    }
    if (!dominated) front.push_back(i);
  }
  return front;
}

Planner::Planner(PlanSpec spec) : spec_(std::move(spec)) {
  if (!spec_.IsValid()) throw InputError(fmt::format("{}: the plan is not complete (gyros, service runs, candidates, target)", spec_.path));
  if (spec_.population) population_.emplace(*spec_.population, spec_.gyro);
}

const model::FitRequest& Planner::ModelOf(size_t c) const {
  const auto& m = spec_.candidates.at(c).model;
  return m ? *m : spec_.model;
}

uint64_t Planner::VerifySeed() const { return sim::Population::GyroSeed(spec_.seed, uint64_t{1} << 63); }

sim::Population::Gyro Planner::Draw(uint64_t suite_seed, uint64_t i) const {
  if (population_) {
    // The population's gyro i; the verification's gyros lie beyond its count, so draw them from
    // a population of the same spread sized to reach them.
    if (i < population_->count()) return population_->Draw(suite_seed, i);
    sim::PopulationSpec bigger = *spec_.population;
    bigger.count = i + 1;
    return sim::Population(bigger, spec_.gyro).Draw(suite_seed, i);
  }
  sim::Population::Gyro g;
  g.index = i;
  g.seed = sim::Population::GyroSeed(suite_seed, i);
  g.config = spec_.gyro;
  return g;
}

model::FitRequest Planner::ScreenedModel(size_t c) const {
  const model::FitRequest& request = ModelOf(c);
  if (model::ParsePolyPreset(request.model) != model::PolyPreset::kAuto) return request;
  // auto selects on noise: on the noise-free runs every term would help. Its selection on the
  // nominal gyro's calibration runs with their noise (the plan's seed; gyro 0's streams) gives
  // the terms the screen's information matrix is made of.
  const sim::Population::Gyro nominal = Draw(spec_.seed, 0);
  std::vector<sim::Run> noisy;
  for (const auto& r : spec_.candidates.at(c).runs) {
    noisy.push_back(sim::SimulateRun(spec_.gyro, r.ToRunSpec(), nominal.seed, CalibrationStream(r)));
  }
  const auto selected = std::get<model::PolyModel>(model::FitModel(sim::Pointers(noisy), request));
  model::FitRequest poly;
  poly.model = "poly";
  poly.channel = selected.spec.channel;
  poly.order = selected.spec.order;
  poly.offset = model::OffsetName(selected.spec.offset);
  poly.beyond_range = selected.spec.extrapolate ? "extrapolate" : "hold";
  poly.reference_C = request.reference_C;
  poly.b0_window_s = request.b0_window_s;
  for (const auto& t : selected.spec.terms) poly.terms.push_back(t.Spelling());
  return poly;
}

ScreenResult Planner::Screen(size_t c) const {
  ScreenResult s;
  const Candidate& cand = spec_.candidates.at(c);
  const sim::GyroConfig g = NoiseFree(spec_.gyro);
  std::vector<sim::Run> calib;
  for (const auto& r : cand.runs) calib.push_back(sim::SimulateRun(g, r.ToRunSpec(), 0, 0));
  std::vector<const sim::Run*> ptrs;
  for (const auto& r : calib) ptrs.push_back(&r);
  std::optional<model::FittedModel> m;
  try {
    m = model::FitModel(ptrs, ScreenedModel(c));
  } catch (const NumericalError& e) {
    s.failure = e.what();
    return s;
  }
  const auto proto = model::ModelRegressors(*m);
  const bool power_on = proto->offset() == model::OffsetRule::kPowerOn;
  std::vector<Eigen::MatrixXd> X;
  std::vector<ScreenNoise> noise;
  for (const auto& r : calib) {
    X.push_back(Rows(*proto, r));
    noise.push_back(NoiseForScreen(spec_.gyro.noise, r.MeanSamplePeriod(), power_on, B0Samples(*proto, r)));
  }
  const Eigen::MatrixXd J = InformationMatrix(X, noise);
  std::vector<double> var;
  for (const auto& sr : spec_.service) {
    const sim::Run run = sim::SimulateRun(g, sr.ToRunSpec(), 0, 0);
    const Eigen::VectorXd xbar = Rows(*proto, run).colwise().mean().transpose();
    const ScreenNoise n = NoiseForScreen(spec_.gyro.noise, run.MeanSamplePeriod(), power_on, B0Samples(*proto, run));
    double v = 0.0;
    try {
      v = CoefficientVariance(J, xbar) + n.white_var / static_cast<double>(run.size()) + n.offset_var;
    } catch (const NumericalError& e) {
      s.failure = e.what();
      return s;
    }
    s.bias_dph.push_back(Score(*m, run).mean);
    var.push_back(v);
    s.sd_dph.push_back(std::sqrt(v));
  }
  s.median_dph = MaxAbsNormalQuantile(s.bias_dph, var, 0.5);
  s.p95_dph = MaxAbsNormalQuantile(s.bias_dph, var, 0.95);
  return s;
}

std::vector<GyroCandidateOutcome> Planner::RunGyro(uint64_t suite_seed, uint64_t i, const std::vector<size_t>& which) const {
  const sim::Population::Gyro g = Draw(suite_seed, i);
  // Each run this gyro needs, simulated once (by its conditions).
  std::map<std::string, sim::Run> calib;
  for (size_t c : which) {
    for (const auto& r : spec_.candidates.at(c).runs) {
      auto [it, fresh] = calib.try_emplace(r.Conditions());
      if (fresh) sim::SimulateRun(g.config, r.ToRunSpec(), g.seed, CalibrationStream(r), &it->second);
    }
  }
  std::vector<sim::Run> service(spec_.service.size());
  for (size_t s = 0; s < service.size(); ++s) {
    sim::SimulateRun(g.config, spec_.service[s].ToRunSpec(), g.seed, ServiceStream(spec_.service[s]), &service[s]);
  }
  std::vector<GyroCandidateOutcome> out(which.size());
  for (size_t k = 0; k < which.size(); ++k) {
    const Candidate& cand = spec_.candidates.at(which[k]);
    std::vector<const sim::Run*> ptrs;
    for (const auto& r : cand.runs) ptrs.push_back(&calib.at(r.Conditions()));
    GyroCandidateOutcome& o = out[k];
    std::optional<model::FittedModel> m;
    try {
      model::FitRequest request = ModelOf(which[k]);
      request.standard_errors = false;  // the service runs score the coefficients alone
      m = model::FitModel(ptrs, request);
    } catch (const NumericalError& e) {
      o.failure = e.what();
      continue;
    }
    for (const auto& run : service) {
      const RunMetrics rm = Score(*m, run);
      o.service_abs_bias.push_back(std::abs(rm.mean));
      o.score = std::max(o.score, std::abs(rm.mean));
      o.stability = std::max(o.stability, rm.stability_100s);
    }
  }
  return out;
}

std::vector<std::vector<GyroCandidateOutcome>> RunGyros(const Planner& planner, uint64_t suite_seed, uint64_t first,
                                                        uint64_t n, const std::vector<size_t>& which, int threads,
                                                        const std::function<void()>& between_gyros) {
  std::vector<std::vector<GyroCandidateOutcome>> per_gyro(n);
  auto run = [&](uint64_t i) {
    if (between_gyros) between_gyros();
    per_gyro[i] = planner.RunGyro(suite_seed, first + i, which);
  };
  // As RunPopulation: --threads N above the core count is the user's choice (parallel.h).
  ParallelFor(n, threads, run);
  std::vector<std::vector<GyroCandidateOutcome>> out(which.size(), std::vector<GyroCandidateOutcome>(n));
  for (uint64_t i = 0; i < n; ++i) {
    for (size_t k = 0; k < which.size(); ++k) out[k][i] = std::move(per_gyro[i][k]);
  }
  return out;
}

PlanShard Planner::Simulate(uint64_t first, uint64_t count, int threads, const std::function<void()>& between_gyros) const {
  if (first > spec_.gyros || count > spec_.gyros - first) {
    throw InputError(fmt::format("{}: gyros {}..{} are not all in a plan of {}", spec_.path, first, first + count, spec_.gyros));
  }
  PlanShard sh;
  sh.first = first;
  sh.count = count;
  const size_t nc = spec_.candidates.size();
  std::vector<size_t> fittable;
  for (size_t c = 0; c < nc; ++c) {
    sh.screens.push_back(Screen(c));
    if (sh.screens.back().failure.empty()) fittable.push_back(c);
  }
  // The screen's choice: the K smallest screened p95 (ties: fewer hours, then plan order).
  sh.kept = fittable;
  if (spec_.screen_keep > 0 && sh.kept.size() > spec_.screen_keep) {
    std::stable_sort(sh.kept.begin(), sh.kept.end(), [&](size_t a, size_t b) {
      const double pa = sh.screens[a].p95_dph, pb = sh.screens[b].p95_dph;
      if (pa != pb) return pa < pb;
      return spec_.candidates[a].ChamberHours() < spec_.candidates[b].ChamberHours();
    });
    sh.kept.resize(spec_.screen_keep);
    std::sort(sh.kept.begin(), sh.kept.end());
  }
  sh.outcomes = RunGyros(*this, spec_.seed, first, count, sh.kept, threads, between_gyros);
  return sh;
}

PlanResult Planner::Run(int threads, uint64_t verify, const std::function<void()>& between_gyros) const {
  return Conclude(Simulate(0, spec_.gyros, threads, between_gyros), threads, verify, between_gyros);
}

PlanResult Planner::Conclude(const PlanShard& sh, int threads, uint64_t verify,
                             const std::function<void()>& between_gyros) const {
  if (sh.first != 0 || sh.count != spec_.gyros || sh.screens.size() != spec_.candidates.size() ||
      sh.outcomes.size() != sh.kept.size()) {
    throw InputError(fmt::format("{}: the outcomes cover gyros {}..{}, not the plan's {}", spec_.path, sh.first,
                                 sh.first + sh.count, spec_.gyros));
  }
  PlanResult r;
  const size_t nc = spec_.candidates.size();
  r.candidates.resize(nc);
  for (size_t c = 0; c < nc; ++c) {
    CandidateResult& cr = r.candidates[c];
    cr.name = spec_.candidates[c].name;
    cr.model = ModelOf(c).model;
    cr.chamber_h = spec_.candidates[c].ChamberHours();
    cr.screen = sh.screens[c];
  }
  const std::vector<size_t>& kept = sh.kept;
  const auto& outcomes = sh.outcomes;
  for (size_t k = 0; k < kept.size(); ++k) {
    CandidateResult& cr = r.candidates[kept[k]];
    cr.simulated = true;
    const auto& o = outcomes[k];
    for (uint64_t i = 0; i < o.size(); ++i) {
      if (!o[i].failure.empty()) {
        cr.failure = fmt::format("gyro {}: {}", i, o[i].failure);
        break;
      }
    }
    if (!cr.failure.empty()) continue;
    std::vector<double> score(o.size()), stab(o.size());
    for (size_t i = 0; i < o.size(); ++i) {
      score[i] = o[i].score;
      stab[i] = o[i].stability;
    }
    cr.abs_bias_after = Summarize(score);
    cr.stability_100s = Summarize(stab);
    for (size_t s = 0; s < spec_.service.size(); ++s) {
      std::vector<double> v(o.size());
      for (size_t i = 0; i < o.size(); ++i) v[i] = o[i].service_abs_bias[s];
      cr.service.push_back(Summarize(v));
    }
    const auto& d = cr.abs_bias_after;
    if (d.p95_hi && *d.p95_hi <= spec_.target_p95_dph) {
      cr.meets = Meets::kYes;
    } else if (d.p95_lo && *d.p95_lo > spec_.target_p95_dph) {
      cr.meets = Meets::kNo;
    } else {
      cr.meets = Meets::kUndecided;
    }
  }
  std::vector<size_t> with;
  std::vector<double> hours, p95;
  for (size_t c = 0; c < nc; ++c) {
    if (!r.candidates[c].has_numbers()) continue;
    with.push_back(c);
    hours.push_back(r.candidates[c].chamber_h);
    p95.push_back(r.candidates[c].abs_bias_after.p95);
  }
  for (size_t k : ParetoFront(hours, p95)) r.candidates[with[k]].pareto = true;
  for (size_t c : with) {
    const auto& cr = r.candidates[c];
    if (cr.meets != Meets::kYes) continue;
    if (!r.recommended) {
      r.recommended = c;
      continue;
    }
    const auto& best = r.candidates[*r.recommended];
    if (cr.chamber_h < best.chamber_h ||
        (cr.chamber_h == best.chamber_h && (cr.abs_bias_after.p95 < best.abs_bias_after.p95 ||
                                            (cr.abs_bias_after.p95 == best.abs_bias_after.p95 && cr.name < best.name)))) {
      r.recommended = c;
    }
  }
  const std::string target = fmt::format("{:g} °/h", spec_.target_p95_dph);
  if (r.recommended) {
    const auto& b = r.candidates[*r.recommended];
    r.reason = fmt::format("the cheapest candidate whose 90 % interval of the p95 |bias after| over {} gyros, {}, lies at "
                           "or below the target {}",
                           spec_.gyros, FormatInterval(b.abs_bias_after), target);
  } else {
    std::vector<std::string> undecided;
    for (size_t c : with)
      if (r.candidates[c].meets == Meets::kUndecided) undecided.push_back(r.candidates[c].name);
    if (with.empty()) {
      r.reason = "no candidate could be fitted and simulated";
    } else if (undecided.empty()) {
      r.reason = fmt::format("no candidate meets the target {}: every simulated candidate's p95 interval lies above it", target);
    } else {
      r.reason = fmt::format("no candidate is shown to meet the target {}: the p95 interval{} of {} reach{} above it "
                             "(more gyros would decide){}",
                             target, undecided.size() == 1 ? "" : "s", fmt::join(undecided, ", "),
                             undecided.size() == 1 ? "es" : "", undecided.size() < with.size() ? ", the others lie above it" : "");
    }
  }
  if (verify > 0) {
    if (!r.recommended) {
      r.reason += "; nothing to verify";
    } else {
      VerifyResult v;
      v.gyros = verify;
      v.seed = VerifySeed();
      const auto o = RunGyros(*this, v.seed, 0, verify, {*r.recommended}, threads, between_gyros);
      std::vector<double> score(verify);
      for (uint64_t i = 0; i < verify; ++i) {
        if (!o[0][i].failure.empty()) throw NumericalError(fmt::format("verification gyro {}: {}", i, o[0][i].failure));
        score[i] = o[0][i].score;
      }
      const Distribution d = Summarize(score);
      v.realised_p95 = d.p95;
      v.realised_lo = d.p95_lo;
      v.realised_hi = d.p95_hi;
      const auto& p = r.candidates[*r.recommended].abs_bias_after;
      v.verdict = VerifyVerdict(p.p95_lo, p.p95_hi, d.p95_lo, d.p95_hi);
      v.consistent = v.verdict == "consistent";
      v.gyros_needed = DrawsToBound(0.95, kPlanIntervalLevel);
      r.verify = v;
    }
  }
  return r;
}

const char* MeetsName(Meets meets) {
  switch (meets) {
    case Meets::kYes: return "yes";
    case Meets::kNo: return "no";
    case Meets::kUndecided: return "undecided";
  }
  return "";
}

std::string VerifyVerdict(std::optional<double> predicted_lo, std::optional<double> predicted_hi,
                          std::optional<double> realised_lo, std::optional<double> realised_hi) {
  const double inf = std::numeric_limits<double>::infinity();
  const double plo = predicted_lo.value_or(-inf), phi = predicted_hi.value_or(inf);
  const double vlo = realised_lo.value_or(-inf), vhi = realised_hi.value_or(inf);
  if (!(plo <= vhi && vlo <= phi)) return "inconsistent";
  const bool closed = predicted_lo && predicted_hi && realised_lo && realised_hi;
  return closed ? "consistent" : "undecided";
}

uint64_t PlanDigest(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(fmt::format("{}: plan file not found", path));
  std::ostringstream text;
  text << in.rdbuf();
  return Fnv1a(text.str());
}

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
    const auto& cr = r.candidates[c];
    const auto& cand = spec.candidates[c];
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
    j["candidates"].push_back(x);
  }
  j["pareto"] = nlohmann::json::array();
  for (const auto& cr : r.candidates)
    if (cr.pareto) j["pareto"].push_back(cr.name);
  j["recommended"] = r.recommended ? nlohmann::json(r.candidates[*r.recommended].name) : nlohmann::json(nullptr);
  j["reason"] = r.reason;
  j["answer"] = PlanAnswer(r);
  if (r.verify) {
    const auto& v = *r.verify;
    const auto& p = r.candidates[*r.recommended].abs_bias_after;
    j["verify"] = {{"candidate", r.candidates[*r.recommended].name},
                   {"gyros", v.gyros},
                   {"seed", v.seed},
                   {"predicted_p95_dph", p.p95},
                   {"predicted_interval_dph", {OptionalNumber(p.p95_lo), OptionalNumber(p.p95_hi)}},
                   {"realised_p95_dph", v.realised_p95},
                   {"realised_interval_dph", {OptionalNumber(v.realised_lo), OptionalNumber(v.realised_hi)}},
                   {"consistent", v.consistent},
                   {"verdict", v.verdict},
                   {"gyros_needed", v.gyros_needed}};
  }
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
    const std::string verdict =
        v.verdict == "consistent"   ? std::string("consistent (the intervals overlap)")
        : v.verdict == "inconsistent" ? std::string("INCONSISTENT (the intervals do not overlap)")
                                      : fmt::format("undecided (an interval open at one end overlaps almost anything: {} "
                                                    "gyros bound the p95's 90 % interval on both sides; --verify {} or "
                                                    "more decides)",
                                                    v.gyros_needed, v.gyros_needed);
    s += fmt::format("\nverify: {} fresh gyros through {}: realised p95 {:.4f} {} against predicted {:.4f} {}: {}\n",
                     v.gyros, r.candidates[*r.recommended].name, v.realised_p95, FormatInterval(realised), p.p95,
                     FormatInterval(p), verdict);
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
