#pragma once
/// Eq. (2) (model/guo2006.h) as a member of the model family (model/causal_regressors.h): the
/// nine regressors Guo2006Row(Ti, Tj, Ti0), Ti0 captured at power-on, with the power-on offset
/// B - B0. Fitted by the family's linear least squares this is the joint fit of FitGuo2006 (the
/// same least squares problem); `rlgtherm compare` uses it to score Eq. (2) on blocks of the
/// training data. `fit` and `compensate` run FitGuo2006 and the Compensator themselves.

#include <array>
#include <memory>
#include <string>
#include <vector>

#include "model/causal_regressors.h"

namespace rlg::model {

class Guo2006Regressors : public CausalRegressors {
 public:
  Guo2006Regressors(const std::array<std::string, 2>& pair, double b0_window_s);
  const std::vector<std::string>& channels() const override { return channels_; }
  const std::vector<std::string>& names() const override { return names_; }
  OffsetRule offset() const override { return OffsetRule::kPowerOn; }
  double b0_window_s() const override { return b0_window_s_; }
  void Reset() override { started_ = false; }
  void Next(double t_s, const double* T, double* row) override;
  std::unique_ptr<CausalRegressors> Clone() const override;

 private:
  std::vector<std::string> channels_, names_;
  double b0_window_s_;
  bool started_ = false;
  double Ti0_ = 0.0;
};

}  // namespace rlg::model
