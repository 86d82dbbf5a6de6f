#pragma once
/// The causal compensation every member of the model family runs (model/causal_regressors.h),
/// sample by sample from power-on:
///
///   fitted offset:    out = B - beta . g(t, T)
///   power-on offset:  out = B - B0 - beta . (g(t, T) - G0)
///
/// B0 as in Eq. (2)'s Compensator (compensation/compensator.h): during the first b0_window_s
/// the running mean of the bias so far, then frozen; beta . G0 likewise the running mean of
/// beta . g over the window for models referred to it (CausalRegressors::ReferredToB0Window),
/// 0 for Eq. (2). Units: °/h. A run fed sample by sample and the same run fed in one loop give
/// the same values to the bit.

#include <Eigen/Dense>
#include <memory>

#include "model/b0_window.h"
#include "model/causal_regressors.h"

namespace rlg::model {

class LinearCompensator {
 public:
  /// `beta` has one value per regressor of `regressors` (copied, then Reset).
  LinearCompensator(const CausalRegressors& regressors, Eigen::VectorXd beta);
  LinearCompensator(const LinearCompensator& other);
  LinearCompensator& operator=(const LinearCompensator& other);

  /// Forgets the run: the next sample is a power-on.
  void Reset();
  /// Compensated bias (°/h) of one sample; `T` the temperatures of regressors().channels().
  double Update(double t_s, const double* T, double bias_dph);

  const CausalRegressors& regressors() const { return *g_; }
  double B0() const { return b0_.value(); }
  bool b0_frozen() const { return b0_.frozen(); }

 private:
  std::unique_ptr<CausalRegressors> g_;
  Eigen::VectorXd beta_, row_;
  B0Window b0_;
  double g0_sum_ = 0.0;  ///< sum of beta . g over the window so far
  double g0_ = 0.0;      ///< beta . G0
};

}  // namespace rlg::model
