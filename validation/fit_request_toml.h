#pragma once
/// A compensation model to fit (model/fit_model.h), from a table of a plan or suite file: a
/// plan's [model] and each candidate's `model = {...}`, a suite's [[fits]]. The keys are those of
/// `rlgtherm fit`: the model's name (under `name_key`: "name" in a plan, "model" in a suite;
/// default guo2006), pair, method, b0_window_s, channel, order, terms, offset, reference_C,
/// beyond_range. A key the named model does not take is refused at its line
/// (model::CheckFitRequest), so that nothing asked for is ignored.

#include <string>

#include "io/toml_reader.h"
#include "model/fit_model.h"

namespace rlg::validation {

/// The request of table `t`; InputError naming the file and line of a wrong key or value. The
/// table's other keys are the caller's: it calls Finish() itself.
model::FitRequest ReadFitRequest(const io::TomlReader& t, const std::string& name_key);

}  // namespace rlg::validation
