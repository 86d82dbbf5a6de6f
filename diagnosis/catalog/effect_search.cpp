#include "diagnosis/catalog/effect_search.h"

#include <algorithm>
#include <cmath>
#include <fmt/format.h>
#include <fmt/ranges.h>

#include "diagnosis/catalog/searches.h"
#include "sim/effect_registry.h"
#include "sim/errors.h"

namespace rlg::diagnosis {

EffectSearch::EffectSearch(const std::string& effect_name, std::map<std::string, ParameterSearch> parameters)
    : effect_(sim::RequireEffect(effect_name)), parameters_(std::move(parameters)) {}

const ParameterSearch& EffectSearch::Parameter(const std::string& name) const {
  static const ParameterSearch kReference{};
  const auto it = parameters_.find(name);
  if (it != parameters_.end()) return it->second;
  const sim::EffectParameter* q = effect_.FindParameter(name);
  if (q != nullptr && q->reference) return kReference;
  throw InputError(fmt::format("{} has no parameter '{}'", effect_.name(), name));
}

bool EffectSearch::Fixed(const std::string& name) const {
  const sim::EffectParameter* q = effect_.FindParameter(name);
  return q != nullptr && q->reference;
}

sim::ParameterMap EffectSearch::Start() const {
  sim::ParameterMap p;
  for (const auto& q : effect_.parameters())
    p[q.name] = q.reference ? q.default_value.value_or(0.0) : Parameter(q.name).start;
  return p;
}

bool EffectSearch::SizeIsSigned() const {
  const auto& ps = effect_.parameters();
  return std::none_of(ps.begin(), ps.end(), [&](const sim::EffectParameter& q) {
    return !q.reference && Parameter(q.name).fit == ParameterSearch::Fit::kSize && q.positive;
  });
}

sim::ParameterMap EffectSearch::Reported(sim::ParameterMap p) const {
  for (const auto& q : effect_.parameters())
    if (q.reference) p.erase(q.name);
  return p;
}

std::vector<BiasRegressor> EffectSearch::Regressors(const TargetSpace&, const std::vector<const Eigen::MatrixXd*>&,
                                                    const ColumnGain&) const {
  return {};
}

std::vector<sim::RangeViolation> EffectSearch::OutsidePlausibleRange(const sim::ParameterMap& reported) const {
  return effect_.OutsidePlausibleRange(FromReported(reported));
}

double EffectSearch::Implausibility(const sim::ParameterMap&) const { return 1.0; }

std::string EffectSearch::SeparationAdvice(const std::set<std::string>&, bool) const { return {}; }

double EffectSearch::Relative(const sim::ParameterMap& reported, const std::string& key, double typical) {
  const auto it = reported.find(key);
  return it == reported.end() ? 1.0 : std::abs(it->second) / typical;
}

const std::vector<std::unique_ptr<const EffectSearch>>& EffectSearches() {
  static const std::vector<std::unique_ptr<const EffectSearch>> table = [] {
    std::vector<std::unique_ptr<const EffectSearch>> v;
    // The catalog's order (sim::Effects()): `diagnose` tries them in it and reports them in it.
    v.push_back(catalog::MissingMassSearch());
    v.push_back(catalog::MissingLinkSearch());
    v.push_back(catalog::PowerDriftSearch());
    v.push_back(catalog::RadiationSearch());
    v.push_back(catalog::SensorLagSearch());
    v.push_back(catalog::SensorOffsetSearch());
    v.push_back(catalog::TemperatureRateSearch());
    v.push_back(catalog::GradientSearch());
    v.push_back(catalog::HysteresisSearch());
    v.push_back(catalog::PlaySearch());
    v.push_back(catalog::ModeHopSearch());
    return v;
  }();
  return table;
}

const EffectSearch* FindSearch(const std::string& name) {
  for (const auto& s : EffectSearches())
    if (s->name() == name) return s.get();
  return nullptr;
}

bool PlausibleSize(const std::string& cause, const sim::ParameterMap& at, const std::string& parameter, double size) {
  const EffectSearch* effect = FindSearch(cause);
  if (effect == nullptr || !std::isfinite(size)) return true;
  for (double sign : {1.0, -1.0}) {
    sim::ParameterMap reported = at;
    reported[parameter] = sign * size;
    if (effect->OutsidePlausibleRange(reported).empty()) return true;
  }
  return false;
}

const EffectSearch& RequireSearch(const std::string& name) {
  if (const EffectSearch* s = FindSearch(name)) return *s;
  sim::RequireEffect(name);  // InputError naming the catalog
  throw InputError(fmt::format("effect '{}' has no search in diagnosis/catalog/", name));
}

}  // namespace rlg::diagnosis
