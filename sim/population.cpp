#include "sim/population.h"

#include <cmath>
#include <fmt/format.h>

#include "sim/errors.h"
#include "sim/noise.h"

namespace rlg::sim {
namespace {

std::string Where(const std::string& file, int line) { return line > 0 ? fmt::format("{}:{}", file, line) : file; }

}  // namespace

bool PopulationSpec::IsValid() const {
  if (count < 1) return false;
  for (const auto& s : spreads) {
    if (!(s.relative_sigma >= 0.0) || !(s.sigma >= 0.0) || !(s.lo <= s.hi)) return false;
  }
  for (const auto& c : correlations) {
    if (!(std::abs(c.coefficient) < 1.0)) return false;
  }
  return true;
}

Population::Population(const PopulationSpec& spec, const GyroConfig& nominal) : spec_(spec), nominal_gyro_(nominal) {
  if (!spec.IsValid()) throw InputError(fmt::format("{}: [population] is not a valid spread", spec.file));
  for (const auto& s : spec_.spreads) {
    const auto matched = MatchParameters(nominal, s.parameter);
    if (matched.empty()) {
      throw InputError(fmt::format("{}: [[population.spread]] parameter '{}' names no parameter of gyro '{}' "
                                   "(names as in scenarios/README.md, \"Populations\", e.g. "
                                   "nodes.block.heat_capacity_J_per_K)",
                                   Where(spec_.file, s.line), s.parameter, nominal.name));
    }
    for (const auto& m : matched) {
      const bool relative = s.kind == Spread::Kind::kLogNormal || (s.kind == Spread::Kind::kNormal && s.sigma == 0.0);
      if (relative && m.get(nominal) == 0.0 && s.relative_sigma > 0.0) {
        throw InputError(fmt::format("{}: parameter '{}' is 0 in gyro '{}', so a relative spread leaves it 0: give "
                                     "a normal spread with sigma in its unit, or a uniform range",
                                     Where(spec_.file, s.line), m.name, nominal.name));
      }
      for (const auto& n : names_) {
        if (n == m.name) {
          throw InputError(fmt::format("{}: parameter '{}' is spread by two [[population.spread]] entries",
                                       Where(spec_.file, s.line), m.name));
        }
      }
      names_.push_back(m.name);
      nominal_.push_back(m.get(nominal));
      params_.push_back(m);
      spread_of_.push_back(&s);
    }
  }
  if (spec_.correlations.empty()) return;
  const size_t n = names_.size();
  std::vector<double> r(n * n, 0.0);
  for (size_t i = 0; i < n; ++i) r[i * n + i] = 1.0;
  auto index = [&](const std::string& name, const Correlation& c) {
    for (size_t i = 0; i < n; ++i) {
      if (names_[i] == name) return i;
    }
    throw InputError(fmt::format("{}: [[population.correlation]] names '{}', which no [[population.spread]] spreads",
                                 Where(spec_.file, c.line), name));
  };
  for (const auto& c : spec_.correlations) {
    const size_t a = index(c.a, c), b = index(c.b, c);
    if (r[a * n + b] != 0.0) {
      throw InputError(fmt::format("{}: a second correlation between '{}' and '{}'", Where(spec_.file, c.line), c.a, c.b));
    }
    r[a * n + b] = r[b * n + a] = c.coefficient;
  }
  // Cholesky, lower: R = L L^T. A pivot <= 0 means R is no correlation matrix (the pairs
  // written contradict each other, e.g. a-b and b-c at 0.9 with a-c at -0.9).
  cholesky_.assign(n * n, 0.0);
  for (size_t j = 0; j < n; ++j) {
    double d = r[j * n + j];
    for (size_t k = 0; k < j; ++k) d -= cholesky_[j * n + k] * cholesky_[j * n + k];
    if (!(d > 1e-12)) {
      throw InputError(fmt::format("{}: the correlations of [[population.correlation]] are not a correlation matrix "
                                   "(not positive definite at '{}'): they contradict each other",
                                   spec_.file, names_[j]));
    }
    const double ljj = std::sqrt(d);
    cholesky_[j * n + j] = ljj;
    for (size_t i = j + 1; i < n; ++i) {
      double s = r[i * n + j];
      for (size_t k = 0; k < j; ++k) s -= cholesky_[i * n + k] * cholesky_[j * n + k];
      cholesky_[i * n + j] = s / ljj;
    }
  }
}

uint64_t Population::GyroSeed(uint64_t suite_seed, uint64_t i) {
  // SplitMix64 (Steele, Lea & Flood 2014) of the pair: neighbouring gyros get unrelated seeds.
  uint64_t z = suite_seed * 0x9E3779B97F4A7C15ULL + (i + 1) * 0xD1B54A32D192ED03ULL;
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
  return z ^ (z >> 31);
}

Population::Gyro Population::Draw(uint64_t suite_seed, uint64_t i) const {
  if (i >= spec_.count) throw InputError(fmt::format("{}: gyro {} is not in a population of {}", spec_.file, i, spec_.count));
  Gyro g;
  g.index = i;
  g.seed = GyroSeed(suite_seed, i);
  g.config = nominal_gyro_;
  const size_t n = params_.size();
  Rng rng(g.seed, kParameterStream);
  std::vector<double> u(n), z(n);
  for (auto& x : u) x = rng.Normal();
  if (cholesky_.empty()) {
    z = u;
  } else {
    for (size_t r = 0; r < n; ++r) {
      double s = 0.0;
      for (size_t k = 0; k <= r; ++k) s += cholesky_[r * n + k] * u[k];
      z[r] = s;
    }
  }
  g.values.resize(n);
  for (size_t k = 0; k < n; ++k) {
    const Spread& s = *spread_of_[k];
    const double x0 = nominal_[k];
    double x = x0;
    switch (s.kind) {
      case Spread::Kind::kNormal:
        x = s.sigma > 0.0 ? x0 + s.sigma * z[k] : x0 * (1.0 + s.relative_sigma * z[k]);
        break;
      case Spread::Kind::kLogNormal:
        x = x0 * std::exp(s.relative_sigma * z[k]);
        break;
      case Spread::Kind::kUniform:
        x = x0 + s.lo + (s.hi - s.lo) * 0.5 * std::erfc(-z[k] / std::sqrt(2.0));  // Phi(z)
        break;
    }
    const GyroParameter& p = params_[k];
    if (!(p.lower_open ? x > p.lower : x >= p.lower) || !std::isfinite(x)) {
      throw InputError(fmt::format("{}: gyro {} draws {} = {:g}, outside its physical range ({} {:g}): the spread "
                                   "written is too wide for a {} distribution (\"lognormal\" stays positive)",
                                   Where(spec_.file, s.line), i, p.name, x, p.lower_open ? ">" : ">=", p.lower,
                                   s.kind == Spread::Kind::kUniform ? "uniform" : "normal"));
    }
    if (!(x <= p.upper)) {
      throw InputError(fmt::format("{}: gyro {} draws {} = {:g}, outside its physical range (<= {:g}): the spread "
                                   "written is too wide",
                                   Where(spec_.file, s.line), i, p.name, x, p.upper));
    }
    p.set(g.config, x);
    g.values[k] = x;
  }
  return g;
}

}  // namespace rlg::sim
