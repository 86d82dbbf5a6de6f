#include <algorithm>
#include "compensation/model_compensator.h"

#include <fmt/format.h>

#include "io/csv.h"
#include "sim/errors.h"

namespace rlg::compensation {
namespace {

std::variant<Compensator, model::LinearCompensator> Make(const model::FittedModel& m) {
  if (const auto* c = std::get_if<model::Guo2006Coefficients>(&m)) return Compensator(*c);
  const auto& p = std::get<model::PolyModel>(m);
  return model::LinearCompensator(model::PolyRegressors(p.spec), p.Beta());
}

}  // namespace

ModelCompensator::ModelCompensator(const model::FittedModel& m) : impl_(Make(m)), channels_(model::ModelChannels(m)) {}

void ModelCompensator::Reset() {
  std::visit([](auto& c) { c.Reset(); }, impl_);
}

double ModelCompensator::Update(double t_s, const double* T, double bias_dph) {
  if (auto* c = std::get_if<Compensator>(&impl_)) return c->Update(t_s, T[0], T[1], bias_dph);
  return std::get<model::LinearCompensator>(impl_).Update(t_s, T, bias_dph);
}

double ModelCompensator::B0() const {
  return std::visit([](const auto& c) { return c.B0(); }, impl_);
}

bool ModelCompensator::b0_frozen() const {
  return std::visit([](const auto& c) { return c.b0_frozen(); }, impl_);
}

std::optional<double> ModelCompensator::Ti0() const {
  const auto* c = std::get_if<Compensator>(&impl_);
  return c ? std::optional<double>(c->Ti0()) : std::nullopt;
}

bool ModelCompensator::OutsideFittedRange() const {
  const auto* c = std::get_if<model::LinearCompensator>(&impl_);
  return c && c->regressors().OutsideFittedRange();
}

std::vector<double> CompensateRun(const model::FittedModel& m, const sim::Run& run, const std::string& bias_column) {
  if (const auto* c = std::get_if<model::Guo2006Coefficients>(&m)) return CompensateRun(*c, run, bias_column);
  ModelCompensator comp(m);
  std::vector<const std::vector<double>*> columns;
  for (const auto& ch : comp.channels()) columns.push_back(&run.Column(ch));
  const auto& b = run.Column(bias_column);
  const double window = model::ModelB0Window(m);
  if (window > 0.0 && (run.size() == 0 || run.t_s.back() < run.t_s.front() + window)) {
    throw InputError(fmt::format("{} lasts {:g} s, shorter than the {:g} s B0 window the model needs", run.Where(),
                                 run.size() == 0 ? 0.0 : run.t_s.back() - run.t_s.front(), window));
  }
  std::vector<double> out(run.size()), T(columns.size());
  for (size_t k = 0; k < run.size(); ++k) {
    for (size_t c = 0; c < columns.size(); ++c) T[c] = (*columns[c])[k];
    out[k] = comp.Update(run.t_s[k], T.data(), b[k]);
  }
  return out;
}

std::string AddCompensatedColumn(const model::FittedModel& m, sim::Trace& trace, const std::string& bias_column) {
  if (const auto* c = std::get_if<model::Guo2006Coefficients>(&m)) return AddCompensatedColumn(*c, trace, bias_column);
  const std::string name = CompensatedColumnName(bias_column);
  for (auto& run : trace.runs) {
    std::vector<double> out = CompensateRun(m, run, bias_column);
    for (double& v : out) v = io::AsWritten(name, v);
    run.AddColumn(name) = std::move(out);
  }
  return name;
}

size_t SamplesOutsideFittedRange(const model::FittedModel& m, const sim::Run& run) {
  const auto* p = std::get_if<model::PolyModel>(&m);
  if (!p) return 0;
  // The regressors' own flag: the channel, and each product factor against its range.
  model::PolyRegressors g(p->spec);
  const std::vector<std::string>& channels = g.channels();
  std::vector<const std::vector<double>*> columns;
  for (const auto& ch : channels) columns.push_back(&run.Column(ch));
  std::vector<double> T(channels.size()), row(g.names().size());
  size_t n = 0;
  for (size_t k = 0; k < run.size(); ++k) {
    for (size_t c = 0; c < channels.size(); ++c) T[c] = (*columns[c])[k];
    g.Next(run.t_s[k], T.data(), row.data());
    n += g.OutsideFittedRange() ? 1 : 0;
  }
  return n;
}

std::string OutsideRangeWarning(const model::PolyModel& p, const sim::Run& run, size_t outside) {
  const bool products = std::any_of(p.spec.terms.begin(), p.spec.terms.end(),
                                    [](const model::PolyTerm& t) { return t.kind == model::TermKind::kProduct; });
  return fmt::format("{}: {}{} leaves the fitted range {:.2f} ... {:.2f} °C{} in {} of {} samples (the polynomial is {} "
                     "there)",
                     run.Where(), p.spec.channel, products ? " or a product term's factor" : "", p.spec.range_C[0],
                     p.spec.range_C[1], products ? " (of " + p.spec.channel + ")" : "", outside, run.size(),
                     p.spec.extrapolate ? "extrapolated" : "held at the range's edge");
}

}  // namespace rlg::compensation
