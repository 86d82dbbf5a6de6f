#pragma once
/// A fitted member of the compensation model family, as one coefficient file holds it
/// (model/coefficients_json.h): the seed paper's Eq. (2) (model/guo2006.h) or a polynomial with
/// its terms (model/poly_model.h, with the presets px4, ardupilot and the selection auto).
/// Both are causal regressors and an offset rule (model/causal_regressors.h); Eq. (2) keeps its
/// own fits and compensator, so that its numbers and files are those of the paper's method.

#include <memory>
#include <string>
#include <variant>
#include <vector>

#include "model/causal_regressors.h"
#include "model/guo2006.h"
#include "model/poly_model.h"

namespace rlg::model {

using FittedModel = std::variant<Guo2006Coefficients, PolyModel>;

/// "guo2006" or "poly": the file's "model" key.
std::string ModelName(const FittedModel& m);
/// For titles: "Eq. (2), pair (T1, T2)", "poly order 3 in T1 (fitted offset) + hysteresis".
std::string ModelTitle(const FittedModel& m);
/// The temperature channels the model reads, in the order its compensator takes them.
std::vector<std::string> ModelChannels(const FittedModel& m);
/// The offset rule's B0 window (s); 0 for a fitted offset.
double ModelB0Window(const FittedModel& m);
/// Every coefficient with its standard error and degrees of freedom (Eq. (2): A10 ... A32).
std::vector<Coefficient> ModelCoefficients(const FittedModel& m);
/// The fit's residual RMS (°/h) and scaled condition number, as the file holds them.
double ModelResidualRms(const FittedModel& m);
double ModelConditionNumber(const FittedModel& m);
/// The model's causal regressors (Eq. (2): Guo2006Regressors).
std::unique_ptr<CausalRegressors> ModelRegressors(const FittedModel& m);

}  // namespace rlg::model
