// The truth side of the blind diagnosis tests (hidden_effects.h): catalog, simulation of a
// hidden case, the part a calibration cannot take up, and the judge of an answer.

#include "tests/diagnosis/hidden_effects.h"
#include "tools/source_dir.h"

#include <boost/random/mersenne_twister.hpp>
#include <boost/random/uniform_real_distribution.hpp>
#include <fmt/format.h>

namespace rlg::test {

const std::vector<CatalogEntry>& HiddenCatalog() {
  static const std::vector<CatalogEntry> c = {
      {"thermal.missing_mass", {"block-cabinet", "anode-cabinet"}, {{"heat_capacity_J_per_K", 200.0}, {"conductance_W_per_K", 0.02}}, "conductance_W_per_K", "conductance_W_per_K"},
      {"thermal.missing_link", {"anode-cathode", "cathode-cabinet", "cathode-ambient"}, {{"conductance_W_per_K", 0.005}}, "conductance_W_per_K", "conductance_W_per_K"},
      {"thermal.power_drift", {"cathode", "anode"}, {{"g_per_C", 0.001}, {"reference_C", 20.0}}, "g_per_C", "g_per_C"},
      {"thermal.radiation", {"block-ambient", "anode-ambient", "cathode-ambient"}, {{"emissivity_area_m2", 0.001}}, "emissivity_area_m2", "emissivity_area_m2"},
      {"sensor.lag", {"T1", "T2", "T3", "T4"}, {{"time_constant_s", 20.0}}, "time_constant_s", "time_constant_s"},
      {"sensor.offset", {"T1", "T2", "T3", "T4"}, {{"offset_C", 0.001}}, "offset_C", "offset_C"},
      // The cathode's only link is to the block: a rate of T4 is exactly a block-cathode
      // gradient, and naming either is right (Judge).
      {"bias.temperature_rate", {"T1", "T4"}, {{"k_dph_per_C_per_min", 0.02}}, "k_dph_per_C_per_min", "k_dph_per_C_per_min"},
      {"bias.gradient", {"anode-cabinet", "cathode-cabinet", "block-cathode"}, {{"k_dph_per_C", 0.01}}, "k_dph_per_C", "k_dph_per_C"},
      {"bias.hysteresis", {"block"}, {{"k_heating_dph_per_C", 0.002}, {"k_cooling_dph_per_C", 0.0}}, "k_heating_dph_per_C", "k_heating_dph_per_C"},
      {"bias.mode_hop", {"block"}, {{"step_dph", 0.02}}, "step_dph", "step_dph"},
  };
  return c;
}

sim::Scenario DiagnosisScenario() {
  return io::LoadScenario(rlg::tools::SourcePath("scenarios/diagnosis-suite.toml"));
}

sim::GyroConfig NominalForDiagnosis() {
  sim::GyroConfig g = DiagnosisScenario().gyro;
  g.calibration_uncertainty = 0.005;
  return g;
}

sim::GyroConfig Noiseless(sim::GyroConfig g) {
  g.noise = sim::GyroNoiseParams{};
  for (auto& s : g.sensors) s.noise = sim::SensorNoiseParams{};
  return g;
}

sim::Scenario Noiseless(sim::Scenario sc) {
  sc.gyro = Noiseless(sc.gyro);
  return sc;
}

double NoiseRms100(const sim::GyroConfig& g, bool bias) {
  if (bias) {
    const double white = 60.0 * g.noise.arw_deg_per_sqrt_h / std::sqrt(100.0);
    return std::hypot(white, 0.664 * g.noise.bias_instability_dph);
  }
  const auto& s = g.sensors.front().noise;
  return std::sqrt((s.sigma_C * s.sigma_C + s.resolution_C * s.resolution_C / 12.0) / 100.0);
}

std::vector<double> Means100(const std::vector<double>& x) {
  std::vector<double> m;
  for (size_t k = 0; k + 100 <= x.size(); k += 100) {
    double sum = 0.0;
    for (size_t i = k; i < k + 100; ++i) sum += x[i];
    m.push_back(sum / 100.0);
  }
  return m;
}

std::vector<std::vector<double>> ChannelMeans100(const sim::Trace& t) {
  std::vector<std::vector<double>> out;
  for (const std::string col : {"T1", "T2", "T3", "T4"}) {
    out.emplace_back();
    for (const auto& run : t.runs) {
      const auto m = Means100(run.Column(col));
      out.back().insert(out.back().end(), m.begin(), m.end());
    }
  }
  return out;
}

CalibrationProjector::CalibrationProjector(const sim::Scenario& clean) : clean_(clean) {
  base_ = ChannelMeans100(sim::SimulateScenario(clean_, 1));
  const auto& net = clean_.gyro.network;
  std::vector<std::function<void(sim::GyroConfig&, double)>> knobs;
  for (size_t i = 0; i < net.nodes.size(); ++i)
    knobs.push_back([i](sim::GyroConfig& g, double f) { g.network.nodes[i].heat_capacity_J_per_K *= f; });
  for (size_t l = 0; l < net.links.size(); ++l)
    if (net.links[l].conductance_W_per_K > 0.0)
      knobs.push_back([l](sim::GyroConfig& g, double f) { g.network.links[l].conductance_W_per_K *= f; });
  for (size_t r = 0; r < net.radiation.size(); ++r)
    if (net.radiation[r].emissivity_area_m2 > 0.0)
      knobs.push_back([r](sim::GyroConfig& g, double f) { g.network.radiation[r].emissivity_area_m2 *= f; });
  for (size_t q = 0; q < net.sources.size(); ++q)
    knobs.push_back([q](sim::GyroConfig& g, double f) {
      for (auto& sh : g.network.sources[q].shares) sh.second *= f;
    });
  const size_t rows = Flat(base_).size();
  J_.resize(static_cast<Eigen::Index>(rows), static_cast<Eigen::Index>(knobs.size()));
  const double step = 1e-3;  // in log units: linear (the prior is 5e-3) and far above round-off
  for (size_t k = 0; k < knobs.size(); ++k) {
    sim::Scenario sc = clean_;
    knobs[k](sc.gyro, std::exp(step));
    J_.col(static_cast<Eigen::Index>(k)) = (Flat(ChannelMeans100(sim::SimulateScenario(sc, 1))) - Flat(base_)) / step;
  }
}

std::pair<double, double> CalibrationProjector::Rms(const sim::EffectSpec& effect, double noise100, double prior_sd) const {
  sim::Scenario sc = clean_;
  sim::ApplyEffect(effect, sc.gyro);
  const Eigen::VectorXd e = Flat(ChannelMeans100(sim::SimulateScenario(sc, 1))) - Flat(base_);
  const double w = 1.0 / (noise100 * noise100), p = 1.0 / (prior_sd * prior_sd);
  const Eigen::MatrixXd A = w * J_.transpose() * J_ + p * Eigen::MatrixXd::Identity(J_.cols(), J_.cols());
  const Eigen::VectorXd x = A.ldlt().solve(w * J_.transpose() * e);
  const Eigen::VectorXd u = e - J_ * x;
  return {LargestChannelRms(e), LargestChannelRms(u)};
}

Eigen::VectorXd CalibrationProjector::Flat(const std::vector<std::vector<double>>& c) const {
  std::vector<double> v;
  for (const auto& ch : c) v.insert(v.end(), ch.begin(), ch.end());
  return Eigen::Map<const Eigen::VectorXd>(v.data(), static_cast<Eigen::Index>(v.size()));
}

double CalibrationProjector::LargestChannelRms(const Eigen::VectorXd& v) const {
  const Eigen::Index per = static_cast<Eigen::Index>(base_.front().size());
  double worst = 0.0;
  for (Eigen::Index c = 0; c * per < v.size(); ++c) worst = std::max(worst, std::sqrt(v.segment(c * per, per).squaredNorm() / per));
  return worst;
}

std::string NodeChannel(const sim::GyroConfig& g, int node) {
  for (const auto& s : g.sensors)
    if (s.node == node && s.lag_time_constants_s.empty()) return s.channel;
  throw std::logic_error("every bias node needs a sensor in the hidden-effect harness");
}

Eigen::MatrixXd BlockMeanNoiseCovariance(const sim::GyroNoiseParams& p, double L, Eigen::Index n) {
  Eigen::VectorXd c = Eigen::VectorXd::Zero(n);
  if (n == 0) return Eigen::MatrixXd(0, 0);
  const double white = 60.0 * p.arw_deg_per_sqrt_h;  // °/h over 1 s
  c[0] += white * white / L;
  for (const auto& [T, s] : sim::GyroNoise::InstabilityTerms(p)) {
    const double a = std::exp(-L / T), r = T / L;
    c[0] += s * s * 2.0 * r * (1.0 - r * (1.0 - a));
    for (Eigen::Index m = 1; m < n; ++m) c[m] += s * s * r * r * (1.0 - a) * (1.0 - a) * std::pow(a, static_cast<double>(m - 1));
  }
  Eigen::MatrixXd S(n, n);
  for (Eigen::Index i = 0; i < n; ++i)
    for (Eigen::Index j = 0; j < n; ++j) S(i, j) = c[std::abs(i - j)];
  return S;
}

BiasProjection ProjectBias(const sim::Trace& without, const sim::Trace& with, const sim::GyroConfig& g,
                           const std::vector<Regressor>& extra,
                           const sim::GyroNoiseParams* noise) {
  std::vector<Eigen::MatrixXd> run_x;  // per run, uncentred regressors (for the noncentrality)
  std::vector<Eigen::VectorXd> run_d;
  // A per-run offset: each run's data and regressors are centred.
  auto centred = [](std::vector<double> v) {
    double m = 0.0;
    for (double y : v) m += y;
    m /= static_cast<double>(v.size());
    for (double& y : v) y -= m;
    return v;
  };
  std::vector<double> e;
  double raw_ss = 0.0;
  const size_t nb = g.bias.langmuir_gradients.size();
  std::vector<std::vector<double>> cols(2 + 2 * nb + extra.size());
  for (size_t r = 0; r < without.runs.size(); ++r) {
    const sim::Run& run = without.runs[r];
    const auto a = Means100(with.runs[r].Column("bias_dph")), b = Means100(run.Column("bias_dph"));
    const auto tb = Means100(run.Column(NodeChannel(g, g.bias.node)));
    std::vector<std::vector<double>> x(cols.size());
    for (size_t i = 0; i < a.size(); ++i) {
      const double dT = tb[i] - g.bias.reference_C;
      x[0].push_back(dT);
      x[1].push_back(dT * dT);
    }
    for (size_t q = 0; q < nb; ++q) {
      const auto& gr = g.bias.langmuir_gradients[q];
      const auto ta = Means100(run.Column(NodeChannel(g, gr.a))), tc = Means100(run.Column(NodeChannel(g, gr.b)));
      for (size_t i = 0; i < a.size(); ++i) {
        x[2 + 2 * q].push_back(ta[i] - tc[i]);
        x[3 + 2 * q].push_back((ta[i] - tc[i]) * (tb[i] - g.bias.reference_C));
      }
    }
    for (size_t j = 0; j < extra.size(); ++j) x[2 + 2 * nb + j] = Means100(extra[j](run));
    std::vector<double> d(a.size());
    for (size_t i = 0; i < a.size(); ++i) {
      d[i] = a[i] - b[i];
      raw_ss += d[i] * d[i];
    }
    if (noise) {
      Eigen::MatrixXd xr(static_cast<Eigen::Index>(d.size()), static_cast<Eigen::Index>(x.size()));
      for (size_t c = 0; c < x.size(); ++c)
        xr.col(static_cast<Eigen::Index>(c)) = Eigen::Map<const Eigen::VectorXd>(x[c].data(), xr.rows());
      run_x.push_back(xr);
      run_d.push_back(Eigen::Map<const Eigen::VectorXd>(d.data(), xr.rows()));
    }
    for (double y : centred(d)) e.push_back(y);
    for (size_t c = 0; c < cols.size(); ++c) {
      const auto v = centred(x[c]);
      cols[c].insert(cols[c].end(), v.begin(), v.end());
    }
  }
  const Eigen::Index n = static_cast<Eigen::Index>(e.size());
  Eigen::MatrixXd X(n, static_cast<Eigen::Index>(cols.size()));
  for (size_t c = 0; c < cols.size(); ++c) X.col(static_cast<Eigen::Index>(c)) = Eigen::Map<const Eigen::VectorXd>(cols[c].data(), n);
  const Eigen::Map<const Eigen::VectorXd> y(e.data(), n);
  const Eigen::VectorXd beta = X.colPivHouseholderQr().solve(y);
  BiasProjection out;
  out.raw = std::sqrt(raw_ss / static_cast<double>(n));
  out.left = std::sqrt((y - X * beta).squaredNorm() / static_cast<double>(n));
  out.blocks = static_cast<int>(n);
  for (size_t j = 0; j < extra.size(); ++j) out.extra_coefficients.push_back(beta[static_cast<Eigen::Index>(2 + 2 * nb + j)]);
  if (noise) {
    // Generalised least squares: each run whitened by the Cholesky factor of its noise
    // covariance, with its own offset column (an offset is not a centring once whitened).
    const auto runs = static_cast<Eigen::Index>(run_x.size()), k = static_cast<Eigen::Index>(cols.size());
    Eigen::MatrixXd A(n, k + runs);
    Eigen::VectorXd b(n);
    Eigen::Index at = 0;
    for (Eigen::Index r = 0; r < runs; ++r) {
      const Eigen::Index m = run_x[r].rows();
      Eigen::MatrixXd xr = Eigen::MatrixXd::Zero(m, k + runs);
      xr.leftCols(k) = run_x[r];
      xr.col(k + r).setOnes();
      const Eigen::LLT<Eigen::MatrixXd> llt(BlockMeanNoiseCovariance(*noise, 100.0, m));
      A.middleRows(at, m) = llt.matrixL().solve(xr);
      b.segment(at, m) = llt.matrixL().solve(run_d[r]);
      at += m;
    }
    out.noncentrality = (b - A * A.colPivHouseholderQr().solve(b)).squaredNorm();
  }
  return out;
}

sim::Trace MakeHiddenCase(const std::string& effect, uint64_t seed, HiddenCase* truth) {
  boost::random::mt19937_64 rng(seed);
  boost::random::uniform_real_distribution<double> u(0.0, 1.0);
  sim::Scenario sc = DiagnosisScenario();
  truth->effect = effect;
  if (effect == "none") return sim::SimulateScenario(sc, seed);
  const CatalogEntry* entry = nullptr;
  for (const auto& e : HiddenCatalog())
    if (e.effect == effect) entry = &e;
  truth->target = entry->targets[static_cast<size_t>(u(rng) * entry->targets.size()) % entry->targets.size()];
  truth->checked = entry->checked;
  truth->strength = 3.0 + 3.0 * u(rng);
  const bool bias = effect.rfind("bias.", 0) == 0;
  const sim::Scenario clean = Noiseless(sc);
  const double noise = NoiseRms100(sc.gyro, bias);
  std::optional<CalibrationProjector> projector;
  std::optional<sim::Trace> without;
  if (bias) {
    without = sim::SimulateScenario(clean, 1);
  } else {
    projector.emplace(clean);
  }
  // (raw, what a calibration leaves) RMS of the effect with parameters q.
  auto rms = [&](const std::map<std::string, double>& q) {
    if (!bias) return projector->Rms({effect, truth->target, q}, noise, NominalForDiagnosis().calibration_uncertainty);
    sim::Scenario with = clean;
    sim::ApplyEffect({effect, truth->target, q}, with.gyro);
    const BiasProjection b = ProjectBias(*without, sim::SimulateScenario(with, 1), clean.gyro);
    return std::make_pair(b.raw, b.left);
  };
  std::map<std::string, double> p = entry->start;
  const double goal = truth->strength * noise;
  for (int iteration = 0; iteration < 3; ++iteration)  // effects are nearly linear in it
    p[entry->scaled] *= goal / rms(p).second;
  const auto [raw, left] = rms(p);
  truth->raw_strength = raw / noise;
  truth->strength = left / noise;  // as reached
  truth->parameters = p;
  sim::ApplyEffect({effect, truth->target, p}, sc.gyro);
  return sim::SimulateScenario(sc, seed);
}

bool SameTarget(const sim::GyroConfig& g, const std::string& effect, const std::string& a, const std::string& b) {
  const std::string ca = diagnosis::CanonicalTarget(g, effect, a), cb = diagnosis::CanonicalTarget(g, effect, b);
  if (ca == cb) return true;
  auto merge = [&](std::string name) {
    if (effect == "bias.gradient") {
      for (const auto& gr : g.bias.langmuir_gradients) {
        const std::string x = g.network.nodes[gr.a].name, y = g.network.nodes[gr.b].name;
        if (name == y) name = x;
      }
    }
    return name;
  };
  if (effect == "bias.gradient") {
    auto split = [&](const std::string& t) {
      const auto d = t.find('-');
      std::string x = merge(t.substr(0, d)), y = merge(t.substr(d + 1));
      if (y < x) std::swap(x, y);
      return x + "-" + y;
    };
    return split(ca) == split(cb);
  }
  if (effect == "thermal.power_drift") {
    for (const auto& src : g.network.sources) {
      bool has_a = false, has_b = false;
      for (const auto& sh : src.shares) {
        has_a = has_a || g.network.nodes[sh.first].name == ca;
        has_b = has_b || g.network.nodes[sh.first].name == cb;
      }
      if (has_a && has_b) return true;
    }
  }
  return false;
}

std::pair<std::string, double> RateAsGradient(const sim::GyroConfig& g, const std::string& rate_target) {
  const int n = g.network.FindNode(diagnosis::CanonicalTarget(g, "bias.temperature_rate", rate_target));
  if (n < 0) return {"", 0.0};
  std::vector<const sim::NetworkSpec::Link*> other;
  for (const auto& l : g.network.links) {
    if (l.conductance_W_per_K <= 0.0 || (l.a != n && l.b != n)) continue;
    const int m = l.a == n ? l.b : l.a;
    bool in_model = false;
    for (const auto& gr : g.bias.langmuir_gradients)
      in_model = in_model || (gr.a == n && gr.b == m) || (gr.a == m && gr.b == n);
    if (!in_model) other.push_back(&l);
  }
  if (other.size() != 1) return {"", 0.0};
  const int m = other.front()->a == n ? other.front()->b : other.front()->a;
  if (m == sim::kAmbient) return {"", 0.0};
  return {g.network.nodes[n].name + "-" + g.network.nodes[m].name,
          60.0 * other.front()->conductance_W_per_K / g.network.nodes[n].heat_capacity_J_per_K};
}

Regressor CandidateRegressor(const sim::GyroConfig& g, const std::string& cause, const std::string& target) {
  if (cause == "bias.gradient") {  // T_a - T_b in the answer's own order
    const auto d = target.find('-');
    const std::string a = NodeChannel(g, g.network.FindNode(diagnosis::CanonicalTarget(g, cause, target.substr(0, d))));
    const std::string b = NodeChannel(g, g.network.FindNode(diagnosis::CanonicalTarget(g, cause, target.substr(d + 1))));
    return [a, b](const sim::Run& run) {
      std::vector<double> x = run.Column(a);
      const auto& xb = run.Column(b);
      for (size_t k = 0; k < x.size(); ++k) x[k] -= xb[k];
      return x;
    };
  }
  if (cause != "bias.temperature_rate" && cause != "bias.hysteresis") return nullptr;
  const std::string ch = NodeChannel(g, g.network.FindNode(diagnosis::CanonicalTarget(g, cause, target)));
  if (cause == "bias.temperature_rate") {
    return [ch](const sim::Run& run) {  // dT/dt in °C/min, central differences
      const auto& T = run.Column(ch);
      std::vector<double> x(T.size());
      for (size_t k = 0; k < T.size(); ++k) {
        const size_t lo = k > 0 ? k - 1 : k, hi = std::min(k + 1, T.size() - 1);
        x[k] = 60.0 * (T[hi] - T[lo]) / (run.t_s[hi] - run.t_s[lo]);
      }
      return x;
    };
  }
  return [ch](const sim::Run& run) {  // heating increments since power-on
    const auto& T = run.Column(ch);
    std::vector<double> x(T.size(), 0.0);
    for (size_t k = 1; k < T.size(); ++k) x[k] = x[k - 1] + std::max(0.0, T[k] - T[k - 1]);
    return x;
  };
}

Verdict Judge(const sim::GyroConfig& g, const HiddenCase& truth, const std::string& cause, const std::string& target) {
  Verdict v;
  if (truth.effect == "none" || cause == "none") {
    v.right = truth.effect == cause;
    v.why = v.right ? "exact" : "wrong cause";
    return v;
  }
  const bool same = cause == truth.effect && SameTarget(g, cause, truth.target, target);
  const Regressor reg = truth.effect.rfind("bias.", 0) == 0 ? CandidateRegressor(g, cause, target) : nullptr;
  if (!reg) {
    v.right = same;
    v.why = same ? "exact" : "a different hypothesis";
    if (same) v.key = truth.checked, v.expected = truth.parameters.at(truth.checked);
    return v;
  }
  // Bias answers: the parameter is the coefficient that fits the truth's signal, in the answer's
  // own orientation and (for hysteresis) its identifiable combination k_heating - k_cooling.
  const sim::Scenario clean = Noiseless(DiagnosisScenario());
  sim::Scenario with = clean;
  sim::ApplyEffect({truth.effect, truth.target, truth.parameters}, with.gyro);
  const sim::GyroNoiseParams noise = DiagnosisScenario().gyro.noise;
  const BiasProjection p =
      ProjectBias(sim::SimulateScenario(clean, 1), sim::SimulateScenario(with, 1), clean.gyro, {reg}, &noise);
  const double lambda = p.noncentrality;
  v.right = same || lambda < kSeparableLambda;
  v.why = same ? "exact" : fmt::format("{} (lambda = {:.2g})", v.right ? "indistinguishable" : "distinguishable", lambda);
  v.key = cause == "bias.gradient"          ? "k_dph_per_C"
          : cause == "bias.temperature_rate" ? "k_dph_per_C_per_min"
                                             : "k_heating_minus_cooling_dph_per_C";
  v.expected = p.extra_coefficients.front();
  return v;
}

std::string TopCandidates(const diagnosis::Diagnosis& d, size_t n) {
  std::string out;
  for (size_t i = 0; i < std::min(n, d.first_candidates.size()); ++i) {
    const auto& c = d.first_candidates[i];
    out += "\n  " + c.cause + " " + c.target + " (" + diagnosis::KindName(c.kind) + ") score " + std::to_string(c.score) +
           " held-out " + std::to_string(c.heldout_rms_ratio);
    for (const auto& [k, v] : c.parameters) out += " " + k + "=" + std::to_string(v);
  }
  return out;
}

std::string TestName(std::string effect) {
  for (auto& ch : effect)
    if (ch == '.') ch = '_';
  return effect;
}

}  // namespace rlg::test
