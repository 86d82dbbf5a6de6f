#pragma once
/// Causal, sample-by-sample compensation with the Eq. (2) model, as a gyro computer runs it
/// (paper: "we sample the first temperature T10 and the average bias of the former two
/// minutes ... then we estimate the current bias and have a real-time compensating"):
///
///   at power-on (first sample):  Ti0 = Ti, a_k = A_k0 + A_k1 Ti0 + A_k2 Ti0²
///   every sample:                out = B - B0 - (a1 dT + a2 dT² + a3 (Tj - Ti))
///
/// B0 is the mean bias over the first window (120 s; model/b0_window.h). During that window the
/// compensator knows only the samples so far and uses their running mean: the causal estimate of
/// B0. After the window B0 is frozen. Batch compensation (CompensateRun) feeds the same object
/// sample by sample, so streaming and batch results are identical to the bit.

#include <string>
#include <vector>

#include "model/b0_window.h"
#include "model/guo2006.h"
#include "sim/trace.h"

namespace rlg::compensation {

using model::B0Window;

class Compensator {
 public:
  explicit Compensator(const model::Guo2006Coefficients& coefficients);

  /// Forgets the run: the next sample is a power-on.
  void Reset();
  /// Compensated bias (°/h) of one sample; samples in time order.
  double Update(double t_s, double Ti, double Tj, double bias_dph);

  double Ti0() const { return Ti0_; }
  double B0() const { return b0_.value(); }
  /// True once the B0 window has passed and B0 is frozen.
  bool b0_frozen() const { return b0_.frozen(); }

 private:
  model::Guo2006Coefficients c_;
  bool started_ = false;
  double Ti0_ = 0.0;
  B0Window b0_;
  Eigen::Vector3d a_ = Eigen::Vector3d::Zero();
};

/// Compensates a whole run: the channels named by the coefficients' pair and `bias_column`
/// (°/h) must exist, and the run must span the B0 window (InputError otherwise).
std::vector<double> CompensateRun(const model::Guo2006Coefficients& coefficients, const sim::Run& run,
                                  const std::string& bias_column = "bias_dph");

/// Compensates `bias_column` of every run of `trace` (CompensateRun) and adds the result as
/// column CompensatedColumnName(bias_column), each value as the tidy CSV writes it
/// (io::AsWritten, 1e-6 °/h): a report on that column and `rlgtherm evaluate` on the file
/// written then agree to the bit. Returns the new column's name.
std::string AddCompensatedColumn(const model::Guo2006Coefficients& coefficients, sim::Trace& trace,
                                 const std::string& bias_column = "bias_dph");

/// The column a compensated `bias_column` is written to: NAME_dph -> NAME_comp_dph (so
/// bias_dph -> bias_comp_dph), any other NAME -> NAME_comp.
std::string CompensatedColumnName(const std::string& bias_column);

}  // namespace rlg::compensation
