#pragma once
/// Eq. (2) of Guo, Xu & Zhao (2006) as C code (compensation/c_export.h): the header, with the
/// model and its fitted range in its first comment, and the source, the coefficients A_kl and
/// the operations of the Compensator (compensation/compensator.h), its sums taken left to right.

#include <string>

#include "compensation/c_export_writer.h"
#include "model/guo2006.h"

namespace rlg::compensation::c_export {

/// <prefix>.h of the coefficients `c`.
std::string Eq2Header(const Writer& w, const model::Guo2006Coefficients& c);
/// <prefix>.c of the coefficients `c`.
std::string Eq2Source(const Writer& w, const model::Guo2006Coefficients& c);

}  // namespace rlg::compensation::c_export
