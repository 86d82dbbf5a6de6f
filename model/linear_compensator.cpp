#include "model/linear_compensator.h"

#include <fmt/format.h>

#include "sim/errors.h"

namespace rlg::model {

LinearCompensator::LinearCompensator(const CausalRegressors& regressors, Eigen::VectorXd beta)
    : g_(regressors.Clone()), beta_(std::move(beta)), row_(beta_.size()) {
  if (static_cast<size_t>(beta_.size()) != g_->names().size()) {
    throw InputError(fmt::format("{} coefficients for {} regressors", beta_.size(), g_->names().size()));
  }
  Reset();
}

LinearCompensator::LinearCompensator(const LinearCompensator& other)
    : g_(other.g_->Clone()), beta_(other.beta_), row_(other.row_.size()) {
  Reset();
}

LinearCompensator& LinearCompensator::operator=(const LinearCompensator& other) {
  if (this != &other) {
    g_ = other.g_->Clone();
    beta_ = other.beta_;
    row_.resize(other.row_.size());
    Reset();
  }
  return *this;
}

void LinearCompensator::Reset() {
  g_->Reset();
  b0_ = B0Window(g_->b0_window_s());
  g0_sum_ = 0.0;
  g0_ = 0.0;
}

double LinearCompensator::Update(double t_s, const double* T, double bias_dph) {
  g_->Next(t_s, T, row_.data());
  const double model = beta_.dot(row_);
  if (g_->offset() == OffsetRule::kPowerOn && b0_.Add(t_s, bias_dph) && g_->ReferredToB0Window()) {
    g0_sum_ += model;
    g0_ = g0_sum_ / static_cast<double>(b0_.count());
  }
  return bias_dph - b0_.value() - (model - g0_);
}

}  // namespace rlg::model
