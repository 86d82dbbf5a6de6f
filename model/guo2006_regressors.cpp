#include "model/guo2006_regressors.h"

#include "model/guo2006.h"

namespace rlg::model {

Guo2006Regressors::Guo2006Regressors(const std::array<std::string, 2>& pair, double b0_window_s)
    : channels_{pair[0], pair[1]},
      names_{"A10", "A11", "A12", "A20", "A21", "A22", "A30", "A31", "A32"},
      b0_window_s_(b0_window_s) {}

void Guo2006Regressors::Next(double, const double* T, double* row) {
  if (!started_) {
    started_ = true;
    Ti0_ = T[0];
  }
  const Row9 r = Guo2006Row(T[0], T[1], Ti0_);
  for (int k = 0; k < 9; ++k) row[k] = r[k];
}

std::unique_ptr<CausalRegressors> Guo2006Regressors::Clone() const {
  return std::make_unique<Guo2006Regressors>(std::array<std::string, 2>{channels_[0], channels_[1]}, b0_window_s_);
}

}  // namespace rlg::model
