#include "validation/plan_planner.h"

#include <algorithm>
#include <cmath>
#include <fmt/format.h>
#include <fmt/ranges.h>
#include <map>

#include "compensation/model_compensator.h"
#include "model/allan.h"
#include "sim/errors.h"
#include "sim/simulator.h"
#include "validation/order_statistics.h"
#include "validation/parallel.h"
#include "validation/plan_screen.h"

namespace rlg::validation {

uint64_t Fnv1a(const std::string& bytes) {
  uint64_t h = 14695981039346656037ull;
  for (unsigned char c : bytes) {
    h ^= c;
    h *= 1099511628211ull;
  }
  return h;
}

namespace {

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

}  // namespace

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


namespace {

// Whether a candidate meets the target, by the interval of its p95 (plan_result.h).
Meets MeetsTarget(const Distribution& d, double target_p95_dph) {
  if (d.p95_hi && *d.p95_hi <= target_p95_dph) return Meets::kYes;
  if (d.p95_lo && *d.p95_lo > target_p95_dph) return Meets::kNo;
  return Meets::kUndecided;
}

// A simulated candidate from its gyros' outcomes: the first fit failure, or the distributions
// of score, stability and |bias after| per service run, and whether it meets the target.
void SummarizeCandidate(const std::vector<GyroCandidateOutcome>& o, const PlanSpec& spec, CandidateResult& cr) {
  cr.simulated = true;
  for (uint64_t i = 0; i < o.size(); ++i) {
    if (!o[i].failure.empty()) {
      cr.failure = fmt::format("gyro {}: {}", i, o[i].failure);
      return;
    }
  }
  std::vector<double> score(o.size()), stab(o.size());
  for (size_t i = 0; i < o.size(); ++i) {
    score[i] = o[i].score;
    stab[i] = o[i].stability;
  }
  cr.abs_bias_after = Summarize(score);
  cr.stability_100s = Summarize(stab);
  for (size_t s = 0; s < spec.service.size(); ++s) {
    std::vector<double> v(o.size());
    for (size_t i = 0; i < o.size(); ++i) v[i] = o[i].service_abs_bias[s];
    cr.service.push_back(Summarize(v));
  }
  cr.meets = MeetsTarget(cr.abs_bias_after, spec.target_p95_dph);
}

// The candidates with numbers, in the plan's order; those on the Pareto front are marked.
std::vector<size_t> MarkParetoFront(PlanResult& r) {
  std::vector<size_t> with;
  std::vector<double> hours, p95;
  for (size_t c = 0; c < r.candidates.size(); ++c) {
    if (!r.candidates[c].has_numbers()) continue;
    with.push_back(c);
    hours.push_back(r.candidates[c].chamber_h);
    p95.push_back(r.candidates[c].abs_bias_after.p95);
  }
  for (size_t k : ParetoFront(hours, p95)) r.candidates[with[k]].pareto = true;
  return with;
}

// The cheapest of `with` that meets the target (ties: lower p95, then name), or none.
std::optional<size_t> Recommend(const PlanResult& r, const std::vector<size_t>& with) {
  std::optional<size_t> best;
  for (size_t c : with) {
    const auto& cr = r.candidates[c];
    if (cr.meets != Meets::kYes) continue;
    if (!best) {
      best = c;
      continue;
    }
    const auto& b = r.candidates[*best];
    if (cr.chamber_h < b.chamber_h ||
        (cr.chamber_h == b.chamber_h && (cr.abs_bias_after.p95 < b.abs_bias_after.p95 ||
                                         (cr.abs_bias_after.p95 == b.abs_bias_after.p95 && cr.name < b.name)))) {
      best = c;
    }
  }
  return best;
}

// Why the recommended candidate, or why none.
std::string Reason(const PlanResult& r, const std::vector<size_t>& with, const PlanSpec& spec) {
  const std::string target = fmt::format("{:g} °/h", spec.target_p95_dph);
  if (r.recommended) {
    const auto& b = r.candidates[*r.recommended];
    return fmt::format("the cheapest candidate whose 90 % interval of the p95 |bias after| over {} gyros, {}, lies at "
                       "or below the target {}",
                       spec.gyros, FormatInterval(b.abs_bias_after), target);
  }
  std::vector<std::string> undecided;
  for (size_t c : with)
    if (r.candidates[c].meets == Meets::kUndecided) undecided.push_back(r.candidates[c].name);
  if (with.empty()) return "no candidate could be fitted and simulated";
  if (undecided.empty()) {
    return fmt::format("no candidate meets the target {}: every simulated candidate's p95 interval lies above it", target);
  }
  return fmt::format("no candidate is shown to meet the target {}: the p95 interval{} of {} reach{} above it "
                     "(more gyros would decide){}",
                     target, undecided.size() == 1 ? "" : "s", fmt::join(undecided, ", "),
                     undecided.size() == 1 ? "es" : "", undecided.size() < with.size() ? ", the others lie above it" : "");
}

// `verify` fresh gyros (Planner::VerifySeed) through the recommended candidate: their p95 and
// its interval against the predicted one.
VerifyResult Verify(const Planner& planner, const PlanResult& r, uint64_t verify, int threads,
                    const std::function<void()>& between_gyros) {
  VerifyResult v;
  v.gyros = verify;
  v.seed = planner.VerifySeed();
  const auto o = RunGyros(planner, v.seed, 0, verify, {*r.recommended}, threads, between_gyros);
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
  v.gyros_needed = DrawsToBound(0.95, kPlanIntervalLevel);
  return v;
}

}  // namespace

PlanResult Planner::Conclude(const PlanShard& sh, int threads, uint64_t verify,
                             const std::function<void()>& between_gyros) const {
  if (sh.first != 0 || sh.count != spec_.gyros || sh.screens.size() != spec_.candidates.size() ||
      sh.outcomes.size() != sh.kept.size()) {
    throw InputError(fmt::format("{}: the outcomes cover gyros {}..{}, not the plan's {}", spec_.path, sh.first,
                                 sh.first + sh.count, spec_.gyros));
  }
  PlanResult r;
  r.candidates.resize(spec_.candidates.size());
  for (size_t c = 0; c < r.candidates.size(); ++c) {
    CandidateResult& cr = r.candidates[c];
    cr.name = spec_.candidates[c].name;
    cr.model = ModelOf(c).model;
    cr.chamber_h = spec_.candidates[c].ChamberHours();
    cr.screen = sh.screens[c];
  }
  for (size_t k = 0; k < sh.kept.size(); ++k) SummarizeCandidate(sh.outcomes[k], spec_, r.candidates[sh.kept[k]]);
  const std::vector<size_t> with = MarkParetoFront(r);
  r.recommended = Recommend(r, with);
  r.reason = Reason(r, with, spec_);
  if (verify > 0) {
    if (!r.recommended) {
      r.reason += "; nothing to verify";
    } else {
      r.verify = Verify(*this, r, verify, threads, between_gyros);
    }
  }
  return r;
}

}  // namespace rlg::validation
