#include "compensation/compensator.h"

#include <fmt/format.h>

#include "io/csv.h"
#include "sim/errors.h"

namespace rlg::compensation {

Compensator::Compensator(const model::Guo2006Coefficients& coefficients)
    : c_(coefficients), b0_(coefficients.b0_window_s) {}

void Compensator::Reset() {
  started_ = false;
  b0_.Reset();
}

double Compensator::Update(double t_s, double Ti, double Tj, double bias_dph) {
  if (!started_) {
    started_ = true;
    Ti0_ = Ti;
    a_ = c_.RunCoefficients(Ti0_);
  }
  b0_.Add(t_s, bias_dph);
  return bias_dph - b0_.value() - a_.dot(model::Guo2006Features(Ti, Tj, Ti0_));
}

std::vector<double> CompensateRun(const model::Guo2006Coefficients& coefficients, const sim::Run& run,
                                  const std::string& bias_column) {
  const auto& Ti = run.Column(coefficients.pair[0]);
  const auto& Tj = run.Column(coefficients.pair[1]);
  const auto& b = run.Column(bias_column);
  if (run.size() == 0 || run.t_s.back() < run.t_s.front() + coefficients.b0_window_s) {
    throw InputError(fmt::format("{} lasts {:g} s, shorter than the {:g} s B0 window the model needs", run.Where(),
                                 run.size() == 0 ? 0.0 : run.t_s.back() - run.t_s.front(), coefficients.b0_window_s));
  }
  Compensator comp(coefficients);
  std::vector<double> out(run.size());
  for (size_t k = 0; k < run.size(); ++k) out[k] = comp.Update(run.t_s[k], Ti[k], Tj[k], b[k]);
  return out;
}

std::string CompensatedColumnName(const std::string& bias_column) {
  const std::string unit = "_dph";
  if (bias_column.size() > unit.size() && bias_column.compare(bias_column.size() - unit.size(), unit.size(), unit) == 0) {
    return bias_column.substr(0, bias_column.size() - unit.size()) + "_comp" + unit;
  }
  return bias_column + "_comp";
}

std::string AddCompensatedColumn(const model::Guo2006Coefficients& coefficients, sim::Trace& trace,
                                 const std::string& bias_column) {
  const std::string name = CompensatedColumnName(bias_column);
  for (auto& run : trace.runs) {
    std::vector<double> out = CompensateRun(coefficients, run, bias_column);  // refuses a run shorter than B0's window
    for (double& v : out) v = io::AsWritten(name, v);
    run.AddColumn(name) = std::move(out);
  }
  return name;
}

}  // namespace rlg::compensation
