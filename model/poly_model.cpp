#include "model/poly_model.h"

#include <algorithm>
#include <fmt/format.h>

namespace rlg::model {

const char* TermKindName(TermKind kind) {
  switch (kind) {
    case TermKind::kRate: return "rate";
    case TermKind::kHysteresis: return "hysteresis";
    case TermKind::kLag: return "lag";
    case TermKind::kGradient: return "gradient";
  }
  return "";
}

std::optional<TermKind> TermKindOf(const std::string& name) {
  for (TermKind k : {TermKind::kRate, TermKind::kHysteresis, TermKind::kLag, TermKind::kGradient})
    if (name == TermKindName(k)) return k;
  return std::nullopt;
}

std::string PolyTerm::Name() const {
  return kind == TermKind::kGradient ? "gradient_" + channel : TermKindName(kind);
}

std::string PolyTerm::Describe() const {
  switch (kind) {
    case TermKind::kRate: return fmt::format("rate (tau_r {:.3g} s)", tau_s);
    case TermKind::kHysteresis: return fmt::format("hysteresis (w {:.3g} °C)", width_C);
    case TermKind::kLag: return fmt::format("lag (tau {:.3g} s)", tau_s);
    case TermKind::kGradient: return "gradient " + channel;
  }
  return "";
}

std::vector<std::string> PolySpec::Channels() const {
  std::vector<std::string> out{channel};
  for (const auto& t : terms)
    if (t.kind == TermKind::kGradient && std::find(out.begin(), out.end(), t.channel) == out.end()) out.push_back(t.channel);
  return out;
}

std::vector<std::string> PolySpec::CoefficientNames() const {
  std::vector<std::string> out;
  if (offset == OffsetRule::kFitted) out.push_back("c0");
  for (int k = 1; k <= order; ++k) out.push_back(fmt::format("c{}", k));
  for (const auto& t : terms) out.push_back(t.Name());
  return out;
}

std::vector<std::string> PolySpec::CoefficientUnits() const {
  std::vector<std::string> out;
  if (offset == OffsetRule::kFitted) out.push_back("°/h");
  for (int k = 1; k <= order; ++k) out.push_back(k == 1 ? "°/h/°C" : fmt::format("°/h/°C^{}", k));
  for (const auto& t : terms) out.push_back(t.kind == TermKind::kRate ? "°/h per °C/min" : "°/h/°C");
  return out;
}

std::string PolySpec::Describe() const {
  std::string s = fmt::format("order {} in {} ({} offset)", order, channel, OffsetName(offset));
  for (const auto& t : terms) s += " + " + (t.kind == TermKind::kGradient ? "gradient " + t.channel : TermKindName(t.kind));
  return s;
}

Eigen::VectorXd PolyModel::Beta() const {
  Eigen::VectorXd b(static_cast<Eigen::Index>(coefficients.size()));
  for (size_t i = 0; i < coefficients.size(); ++i) b[static_cast<Eigen::Index>(i)] = coefficients[i].value;
  return b;
}

PolyRegressors::PolyRegressors(const PolySpec& spec)
    : spec_(spec), channels_(spec.Channels()), names_(spec.CoefficientNames()) {
  for (const auto& t : spec_.terms) {
    size_t index = 0;
    if (t.kind == TermKind::kGradient) index = static_cast<size_t>(std::find(channels_.begin(), channels_.end(), t.channel) - channels_.begin());
    if (t.kind == TermKind::kRate) {
      index = rate_.size();
      rate_.emplace_back(t.tau_s);
    } else if (t.kind == TermKind::kHysteresis) {
      index = play_.size();
      play_.emplace_back(t.width_C);
    } else if (t.kind == TermKind::kLag) {
      index = lag_.size();
      lag_.emplace_back(t.tau_s);
    }
    term_channel_.push_back(index);
  }
}

void PolyRegressors::Reset() {
  outside_ = false;
  for (auto& r : rate_) r.Reset();
  for (auto& p : play_) p.Reset();
  for (auto& l : lag_) l.Reset();
}

void PolyRegressors::Next(double t_s, const double* T, double* row) {
  const double t = T[0];
  const double clipped = std::clamp(t, spec_.range_C[0], spec_.range_C[1]);
  outside_ = t < spec_.range_C[0] || t > spec_.range_C[1];
  const double d = clipped - spec_.reference_C;
  size_t at = 0;
  if (spec_.offset == OffsetRule::kFitted) row[at++] = 1.0;
  double power = 1.0;
  for (int k = 1; k <= spec_.order; ++k) {
    power *= d;
    row[at++] = power;
  }
  for (size_t i = 0; i < spec_.terms.size(); ++i) {
    const size_t j = term_channel_[i];
    switch (spec_.terms[i].kind) {
      case TermKind::kRate: row[at++] = rate_[j].Next(t_s, t); break;
      case TermKind::kHysteresis: row[at++] = t - play_[j].Next(t); break;
      case TermKind::kLag: row[at++] = lag_[j].Next(t_s, t) - t; break;
      case TermKind::kGradient: row[at++] = T[j] - t; break;
    }
  }
}

}  // namespace rlg::model
