#pragma once
/// Causal compensation with any member of the model family (model/compensation_model.h), sample
/// by sample from power-on: Eq. (2) through its own Compensator (compensator.h), so its output is
/// that of the paper's method to the bit; the polynomial models through the family's
/// LinearCompensator (model/linear_compensator.h), fed the same regressors their fit used.
/// Batch compensation (CompensateRun) and streaming (stream.h) feed the same object in a loop,
/// so their results are identical to the bit.

#include <optional>
#include <string>
#include <variant>
#include <vector>

#include "compensation/compensator.h"
#include "model/compensation_model.h"
#include "model/linear_compensator.h"
#include "sim/trace.h"

namespace rlg::compensation {

class ModelCompensator {
 public:
  explicit ModelCompensator(const model::FittedModel& model);

  /// The temperature channels Update takes, in order (Eq. (2): its pair).
  const std::vector<std::string>& channels() const { return channels_; }
  /// Forgets the run: the next sample is a power-on.
  void Reset();
  /// Compensated bias (°/h) of one sample; `T` the temperatures of channels(), in order.
  double Update(double t_s, const double* T, double bias_dph);
  /// B0 so far (°/h; 0 for a fitted offset) and whether its window has passed.
  double B0() const;
  bool b0_frozen() const;
  /// Eq. (2)'s Ti0 (the first sample's Ti); nullopt for the other models.
  std::optional<double> Ti0() const;
  /// The last sample lay outside the polynomial's fitted range (its channel's, or a product
  /// factor's): held at the edge or extrapolated, as the model says (model/poly_model.h).
  bool OutsideFittedRange() const;

 private:
  std::variant<Compensator, model::LinearCompensator> impl_;
  std::vector<std::string> channels_;
};

/// Compensates a whole run: the model's channels and `bias_column` (°/h) must exist, and a run of
/// a power-on model must span its B0 window (InputError otherwise, as for Eq. (2)).
std::vector<double> CompensateRun(const model::FittedModel& model, const sim::Run& run,
                                  const std::string& bias_column = "bias_dph");

/// CompensateRun over every run, added as column CompensatedColumnName(bias_column), each value
/// as the tidy CSV writes it (compensator.h's AddCompensatedColumn, for any model).
std::string AddCompensatedColumn(const model::FittedModel& model, sim::Trace& trace,
                                 const std::string& bias_column = "bias_dph");

/// How many samples of `run` lie outside a polynomial model's fitted range (its channel's, or a
/// product factor's: PolyRegressors::OutsideFittedRange; 0 for Eq. (2), whose range is about Ti0).
size_t SamplesOutsideFittedRange(const model::FittedModel& model, const sim::Run& run);

/// The warning `compensate` and Python give for `outside` such samples of `run`.
std::string OutsideRangeWarning(const model::PolyModel& model, const sim::Run& run, size_t outside);

}  // namespace rlg::compensation
