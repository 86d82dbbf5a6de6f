#include "model/poly_model.h"

#include <algorithm>
#include <cctype>
#include <fmt/format.h>
#include <map>

namespace rlg::model {

const char* PolyPresetName(PolyPreset preset) {
  switch (preset) {
    case PolyPreset::kPoly: return "poly";
    case PolyPreset::kPx4: return "px4";
    case PolyPreset::kArduPilot: return "ardupilot";
    case PolyPreset::kAuto: return "auto";
  }
  return "";
}

std::optional<PolyPreset> ParsePolyPreset(std::string_view name) {
  for (const PolyPreset p : {PolyPreset::kPoly, PolyPreset::kPx4, PolyPreset::kArduPilot, PolyPreset::kAuto})
    if (name == PolyPresetName(p)) return p;
  return std::nullopt;
}

const char* TermKindName(TermKind kind) {
  switch (kind) {
    case TermKind::kRate: return "rate";
    case TermKind::kHysteresis: return "hysteresis";
    case TermKind::kLag: return "lag";
    case TermKind::kGradient: return "gradient";
    case TermKind::kProduct: return "product";
  }
  return "";
}

std::optional<TermKind> TermKindOf(const std::string& name) {
  for (TermKind k : {TermKind::kRate, TermKind::kHysteresis, TermKind::kLag, TermKind::kGradient, TermKind::kProduct})
    if (name == TermKindName(k)) return k;
  return std::nullopt;
}

std::string Factor::Name() const {
  const std::string signal = minus.empty() ? channel : channel + "-" + minus;
  if (rate) return "rate(" + signal + ")";
  return minus.empty() ? signal : "(" + signal + ")";
}

bool Factor::operator<(const Factor& o) const {
  if (rate != o.rate) return !rate;
  if (minus.empty() != o.minus.empty()) return minus.empty();
  if (channel != o.channel) return channel < o.channel;
  return minus < o.minus;
}

namespace {

/// The canonical spelling of a product: its factors in order, a run of one factor as ^k.
std::string ProductName(const std::vector<Factor>& factors) {
  std::string s;
  for (size_t i = 0; i < factors.size();) {
    size_t j = i + 1;
    while (j < factors.size() && factors[j].SameSignal(factors[i])) ++j;
    if (!s.empty()) s += "*";
    s += factors[i].Name();
    if (j - i > 1) s += fmt::format("^{}", j - i);
    i = j;
  }
  return s;
}

}  // namespace

std::string PolyTerm::Name() const {
  if (kind == TermKind::kProduct) return ProductName(factors);
  return kind == TermKind::kGradient ? "gradient_" + channel : TermKindName(kind);
}

std::string PolyTerm::Spelling() const {
  if (kind == TermKind::kProduct) return ProductName(factors);
  return kind == TermKind::kGradient ? "gradient:" + channel : TermKindName(kind);
}

bool PolyTerm::HasRate() const {
  return std::any_of(factors.begin(), factors.end(), [](const Factor& f) { return f.rate; });
}

std::string PolyTerm::CoefficientUnit() const {
  int temperatures = 0, rates = 0;
  switch (kind) {
    case TermKind::kRate: rates = 1; break;
    case TermKind::kProduct:
      for (const auto& f : factors) (f.rate ? rates : temperatures) += 1;
      break;
    default: temperatures = 1; break;
  }
  std::string u = "°/h";
  if (temperatures > 0) u += temperatures == 1 ? "/°C" : fmt::format("/°C^{}", temperatures);
  if (rates > 0) u += rates == 1 ? " per °C/min" : fmt::format(" per (°C/min)^{}", rates);
  return u;
}

namespace {

/// A channel name at `at` in `s` (T followed by letters, digits or '_'); empty when none.
std::string ReadChannel(const std::string& s, size_t& at) {
  if (at >= s.size() || s[at] != 'T') return {};
  size_t end = at + 1;
  while (end < s.size() && (std::isalnum(static_cast<unsigned char>(s[end])) || s[end] == '_')) ++end;
  if (end == at + 1) return {};
  std::string name = s.substr(at, end - at);
  at = end;
  return name;
}

/// One signal "Tj" or "Tj-Tk" at `at`.
bool ReadSignal(const std::string& s, size_t& at, Factor& f) {
  f.channel = ReadChannel(s, at);
  if (f.channel.empty()) return false;
  if (at < s.size() && s[at] == '-') {
    ++at;
    f.minus = ReadChannel(s, at);
    if (f.minus.empty() || f.minus == f.channel) return false;
  }
  return true;
}

/// The factors of a product spelling (spaces removed); false for anything else.
bool ParseFactors(const std::string& s, std::vector<Factor>& out) {
  size_t at = 0;
  for (;;) {
    Factor f;
    if (s.compare(at, 5, "rate(") == 0) {
      at += 5;
      f.rate = true;
      if (!ReadSignal(s, at, f) || at >= s.size() || s[at] != ')') return false;
      ++at;
    } else if (at < s.size() && s[at] == '(') {
      ++at;
      if (!ReadSignal(s, at, f) || f.minus.empty() || at >= s.size() || s[at] != ')') return false;
      ++at;
    } else if (!ReadSignal(s, at, f)) {
      return false;
    }
    int power = 1;
    if (at < s.size() && s[at] == '^') {
      ++at;
      if (at >= s.size() || s[at] < '1' || s[at] > '4') return false;
      power = s[at++] - '0';
    }
    for (int k = 0; k < power; ++k) out.push_back(f);
    if (at == s.size()) break;
    if (s[at] != '*') return false;
    ++at;
  }
  return !out.empty();
}

}  // namespace

std::optional<PolyTerm> ParseTerm(const std::string& text, const std::string& channel, std::string* error) {
  std::string s;
  for (char c : text)
    if (!std::isspace(static_cast<unsigned char>(c))) s += c;
  PolyTerm t;
  const size_t colon = s.find(':');
  const std::string kind = s.substr(0, colon);
  if (kind == "gradient" && colon != std::string::npos) {
    t.kind = TermKind::kGradient;
    t.channel = s.substr(colon + 1);
    size_t at = 0;
    if (t.channel.empty() || ReadChannel(t.channel, at) != t.channel) {
      if (error) *error = fmt::format("term '{}': expected gradient:<channel> such as gradient:T2", text);
      return std::nullopt;
    }
    return t;
  }
  if (colon == std::string::npos && TermKindOf(kind) && kind != "product") {
    t.kind = *TermKindOf(kind);
    return t;
  }
  std::vector<Factor> factors;
  if (colon != std::string::npos || !ParseFactors(s, factors) || factors.size() > 4) {
    if (error) {
      *error = fmt::format("term '{}': expected rate, hysteresis, lag, gradient, gradient:<channel>, or a product of up "
                           "to four factors Tj, (Tj-Tk), rate(Tj), rate(Tj-Tk) joined by '*' with optional ^2..^4, "
                           "such as T1*(T2-T1)",
                           text);
    }
    return std::nullopt;
  }
  std::sort(factors.begin(), factors.end());
  if (factors.size() == 1 && factors[0].minus == channel && !factors[0].rate) {
    t.kind = TermKind::kGradient;  // (Tj-T): the gradient term
    t.channel = factors[0].channel;
    return t;
  }
  if (factors.size() == 1 && factors[0].rate && factors[0].channel == channel && factors[0].minus.empty()) {
    t.kind = TermKind::kRate;  // rate(T): the rate term
    return t;
  }
  bool powers_of_channel = true;  // T^k: the polynomial's own
  for (const auto& f : factors) powers_of_channel = powers_of_channel && f.channel == channel && f.minus.empty() && !f.rate;
  if (powers_of_channel) {
    if (error) {
      *error = fmt::format("term '{}': powers of the model's channel {} are its polynomial; set the order instead", text,
                           channel);
    }
    return std::nullopt;
  }
  t.kind = TermKind::kProduct;
  t.factors = std::move(factors);
  return t;
}

std::string PolyTerm::Describe() const {
  switch (kind) {
    case TermKind::kRate: return fmt::format("rate (tau_r {:.3g} s)", tau_s);
    case TermKind::kHysteresis: return fmt::format("hysteresis (w {:.3g} °C)", width_C);
    case TermKind::kLag: return fmt::format("lag (tau {:.3g} s)", tau_s);
    case TermKind::kGradient: return "gradient " + channel;
    case TermKind::kProduct: return HasRate() ? fmt::format("{} (tau_r {:.3g} s)", Name(), tau_s) : Name();
  }
  return "";
}

std::vector<std::string> PolySpec::Channels() const {
  std::vector<std::string> out{channel};
  auto add = [&](const std::string& ch) {
    if (!ch.empty() && std::find(out.begin(), out.end(), ch) == out.end()) out.push_back(ch);
  };
  for (const auto& t : terms) {
    if (t.kind == TermKind::kGradient) add(t.channel);
    for (const auto& f : t.factors) {
      add(f.channel);
      add(f.minus);
    }
  }
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
  for (const auto& t : terms) out.push_back(t.CoefficientUnit());
  return out;
}

std::string PolySpec::Describe() const {
  std::string s = fmt::format("order {} in {} ({} offset)", order, channel, OffsetName(offset));
  for (const auto& t : terms) {
    s += " + " + (t.kind == TermKind::kGradient ? "gradient " + t.channel
                  : t.kind == TermKind::kProduct ? t.Name()
                                                 : std::string(TermKindName(t.kind)));
  }
  if (extrapolate) s += ", extrapolated beyond its range";
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
    product_.emplace_back();
    for (const auto& f : t.factors) {
      auto at = [&](const std::string& ch) {
        return static_cast<size_t>(std::find(channels_.begin(), channels_.end(), ch) - channels_.begin());
      };
      FactorSlot slot;
      slot.a = at(f.channel);
      slot.minus = f.minus.empty() ? -1 : static_cast<long>(at(f.minus));
      slot.range = f.range;
      if (f.rate) {
        slot.rate = static_cast<long>(rate_.size());
        rate_.emplace_back(t.tau_s);
      }
      product_.back().push_back(slot);
    }
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
  const double clipped = spec_.extrapolate ? t : std::clamp(t, spec_.range_C[0], spec_.range_C[1]);
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
      case TermKind::kProduct: {
        double value = 1.0;
        for (const FactorSlot& slot : product_[i]) {
          double v = slot.minus < 0 ? T[slot.a] : T[slot.a] - T[static_cast<size_t>(slot.minus)];
          if (slot.rate >= 0) v = rate_[static_cast<size_t>(slot.rate)].Next(t_s, v);
          outside_ = outside_ || v < slot.range[0] || v > slot.range[1];
          if (!spec_.extrapolate) v = std::clamp(v, slot.range[0], slot.range[1]);
          if (slot.minus < 0 && slot.rate < 0) v -= spec_.reference_C;
          value *= v;
        }
        row[at++] = value;
        break;
      }
    }
  }
}

}  // namespace rlg::model
