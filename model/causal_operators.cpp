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
    rate_ += -std::expm1(-dt / tau_s_) * (difference - rate_);
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
    const double x = dt / tau_s_;
    const double one_minus_a = -std::expm1(-x);
    // phi = 1 - (1 - a) / x, by its series below x = 1e-4 (the difference loses digits there).
    const double phi = x < 1e-4 ? x * (0.5 - x / 6.0) : 1.0 - one_minus_a / x;
    lag_ = (1.0 - one_minus_a) * lag_ + one_minus_a * T_ + (T - T_) * phi;
    t_ = t_s;
    T_ = T;
  }
  return lag_;
}

}  // namespace rlg::model
