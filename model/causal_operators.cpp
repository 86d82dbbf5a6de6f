#include "model/causal_operators.h"

#include <algorithm>
#include <cmath>

namespace rlg::model {

double RateFilter::Next(double t_s, double T) {
  if (!started_) {
    started_ = true;
    t_ = t_s;
    T_ = T;
    rate_ = 0.0;
    return rate_;
  }
  const double dt = t_s - t_;
  if (dt > 0.0) {
    const double difference = 60.0 * (T - T_) / dt;
    if (dt != dt_) {  // regular samples: one expm1 a run
      dt_ = dt;
      gain_ = -std::expm1(-dt / tau_s_);
    }
    rate_ += gain_ * (difference - rate_);
    t_ = t_s;
    T_ = T;
  }
  return rate_;
}

double PlayOperator::Next(double T) {
  if (!started_) {
    started_ = true;
    p_ = T;
  }
  p_ = std::clamp(p_, T - half_, T + half_);
  return p_;
}

double FirstOrderLag::Next(double t_s, double T) {
  if (!started_) {
    started_ = true;
    t_ = t_s;
    T_ = T;
    lag_ = T;
    return lag_;
  }
  const double dt = t_s - t_;
  if (dt > 0.0) {
    if (dt != dt_) {  // regular samples: one expm1 a run
      dt_ = dt;
      const double x = dt / tau_s_;
      one_minus_a_ = -std::expm1(-x);
      // phi = 1 - (1 - a) / x, by its series below x = 1e-4 (the difference loses digits there).
      phi_ = x < 1e-4 ? x * (0.5 - x / 6.0) : 1.0 - one_minus_a_ / x;
    }
    const double one_minus_a = one_minus_a_, phi = phi_;
    lag_ = (1.0 - one_minus_a) * lag_ + one_minus_a * T_ + (T - T_) * phi;
    t_ = t_s;
    T_ = T;
  }
  return lag_;
}

}  // namespace rlg::model
