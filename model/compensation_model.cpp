#include "model/compensation_model.h"

#include <fmt/format.h>

#include "model/guo2006_regressors.h"

namespace rlg::model {

namespace {
template <class... Ts>
struct Overloaded : Ts... {
  using Ts::operator()...;
};
template <class... Ts>
Overloaded(Ts...) -> Overloaded<Ts...>;
}  // namespace

std::string ModelName(const FittedModel& m) { return std::holds_alternative<Guo2006Coefficients>(m) ? "guo2006" : "poly"; }

std::string ModelTitle(const FittedModel& m) {
  return std::visit(Overloaded{[](const Guo2006Coefficients& c) { return fmt::format("Eq. (2), pair ({}, {})", c.pair[0], c.pair[1]); },
                               [](const PolyModel& p) { return "poly " + p.spec.Describe(); }},
                    m);
}

std::vector<std::string> ModelChannels(const FittedModel& m) {
  return std::visit(Overloaded{[](const Guo2006Coefficients& c) { return std::vector<std::string>{c.pair[0], c.pair[1]}; },
                               [](const PolyModel& p) { return p.spec.Channels(); }},
                    m);
}

double ModelB0Window(const FittedModel& m) {
  return std::visit(Overloaded{[](const Guo2006Coefficients& c) { return c.b0_window_s; },
                               [](const PolyModel& p) { return p.spec.offset == OffsetRule::kPowerOn ? p.spec.b0_window_s : 0.0; }},
                    m);
}

std::vector<Coefficient> ModelCoefficients(const FittedModel& m) {
  if (const auto* p = std::get_if<PolyModel>(&m)) return p->coefficients;
  const auto& c = std::get<Guo2006Coefficients>(m);
  std::vector<Coefficient> out;
  for (int k = 0; k < 3; ++k) {
    for (int l = 0; l < 3; ++l) {
      Coefficient e;
      e.name = fmt::format("A{}{}", k + 1, l);
      const int power = (k == 1 ? 2 : 1) + l;
      e.unit = power == 1 ? "°/h/°C" : fmt::format("°/h/°C^{}", power);
      e.value = c.A(k, l);
      e.standard_error = c.A_stderr(k, l);
      e.dof = c.stderr_dof(k, l);
      out.push_back(e);
    }
  }
  return out;
}

double ModelResidualRms(const FittedModel& m) {
  return std::visit([](const auto& c) { return c.residual_rms_dph; }, m);
}

double ModelConditionNumber(const FittedModel& m) {
  return std::visit([](const auto& c) { return c.condition_number; }, m);
}

std::unique_ptr<CausalRegressors> ModelRegressors(const FittedModel& m) {
  if (const auto* p = std::get_if<PolyModel>(&m)) return std::make_unique<PolyRegressors>(p->spec);
  const auto& c = std::get<Guo2006Coefficients>(m);
  return std::make_unique<Guo2006Regressors>(c.pair, c.b0_window_s);
}

}  // namespace rlg::model
