#pragma once
/// The polynomial family (model/poly_model.h: PX4's and ArduPilot's cubics, `poly`, `auto`) as C
/// code (compensation/c_export.h): the header, with the model, its terms and their fitted ranges
/// in its first comment, and the source, the coefficients and the operations of the
/// LinearCompensator (model/linear_compensator.h) on the causal operators
/// (model/causal_operators.h), its sums taken left to right.

#include <string>

#include "compensation/c_export_writer.h"
#include "model/poly_model.h"

namespace rlg::compensation::c_export {

/// <prefix>.h of the model `m`.
std::string PolyHeader(const Writer& w, const model::PolyModel& m);
/// <prefix>.c of the model `m`.
std::string PolySource(const Writer& w, const model::PolyModel& m);

}  // namespace rlg::compensation::c_export
