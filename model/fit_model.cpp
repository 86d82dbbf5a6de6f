#include "model/fit_model.h"

#include <fmt/format.h>

#include "model/model_selection.h"
#include "model/poly_fit.h"
#include "sim/errors.h"

namespace rlg::model {
namespace {

OffsetRule ParseOffset(const std::string& text) {
  if (text == "fitted") return OffsetRule::kFitted;
  if (text == "power_on") return OffsetRule::kPowerOn;
  throw InputError(fmt::format("offset '{}': expected fitted or power_on", text));
}

}  // namespace

std::string ResolveModelName(const FitRequest& r, const std::vector<const sim::Run*>& runs) {
  if (!r.model.empty()) return r.model;
  if (r.pair) return "guo2006";
  const std::array<std::string, 2> pair{"T1", "T2"};
  bool both = !runs.empty();
  for (const sim::Run* run : runs) both = both && run->Has(pair[0]) && run->Has(pair[1]);
  return both ? "guo2006" : "poly";
}

void CheckFitRequest(const std::string& name, const FitRequest& r) {
  if (name == "guo2006") {
    if (r.channel || r.order || !r.terms.empty() || r.offset || r.reference_C || r.beyond_range) {
      throw InputError("channel, order, terms, offset, reference and beyond_range are options of the polynomial models "
                       "(poly, px4, ardupilot, auto); Eq. (2) (guo2006) takes a pair");
    }
    // Its gradient term Tj - Ti would be zero in every sample: a usage error, not the
    // numerical failure the fit would report.
    if (r.pair && (*r.pair)[0] == (*r.pair)[1]) {
      throw InputError(fmt::format("pair ({0}, {0}): the same channel twice; Eq. (2) takes two channels (Ti, Tj), its "
                                   "gradient term being Tj - Ti",
                                   (*r.pair)[0]));
    }
    return;
  }
  if (name != "poly" && name != "px4" && name != "ardupilot" && name != "auto") {
    throw InputError(fmt::format("model '{}': expected guo2006, poly, px4, ardupilot or auto", name));
  }
  if (r.pair || r.method) throw InputError(fmt::format("pair and method are options of Eq. (2) (guo2006), not of {}", name));
  if (name != "poly" && r.order) throw InputError(fmt::format("order: {} chooses its own; order is an option of poly", name));
  if ((name == "px4" || name == "ardupilot") && r.offset) {
    throw InputError(fmt::format("offset: {}'s offset rule is part of it ({}); offset is an option of poly and auto", name,
                                 name == "px4" ? "fitted" : "power_on"));
  }
  if ((name == "px4" || name == "ardupilot") && !r.terms.empty()) {
    throw InputError(fmt::format("terms: {} is a cubic alone; for a cubic with terms fit poly with order 3", name));
  }
  if (r.offset) ParseOffset(*r.offset);
  for (const auto& t : r.terms) {  // read as the fit reads them, before any data ("gradient": every other channel)
    std::string why;
    if (t != "gradient" && !ParseTerm(t, r.channel.value_or("T1"), &why)) throw InputError(fmt::format("{}: {}", name, why));
  }
  if (r.beyond_range) {
    if (name != "poly") {
      throw InputError(fmt::format("beyond_range: {} {}; beyond_range is an option of poly", name,
                                   name == "auto" ? "extrapolates (its search scored it beyond the range)" : "holds at the range's edge"));
    }
    if (*r.beyond_range != "hold" && *r.beyond_range != "extrapolate") {
      throw InputError(fmt::format("beyond_range '{}': expected hold or extrapolate", *r.beyond_range));
    }
  }
}

FittedModel FitModel(const std::vector<const sim::Run*>& runs, const FitRequest& r) {
  const std::string name = ResolveModelName(r, runs);
  CheckFitRequest(name, r);
  if (name == "guo2006") {
    FitOptions o;
    if (r.pair) o.pair = *r.pair;
    const std::string method = r.method.value_or("joint");
    if (method == "joint") o.method = FitOptions::Method::kJoint;
    else if (method == "two_stage") o.method = FitOptions::Method::kTwoStage;
    else throw InputError(fmt::format("method '{}': expected joint or two_stage", method));
    o.b0_window_s = r.b0_window_s;
    return FitGuo2006(runs, o);
  }
  const std::string channel = r.channel.value_or("T1");
  if (name == "auto") {
    AutoOptions o;
    o.channel = channel;
    if (r.offset) o.offset = ParseOffset(*r.offset);
    o.reference_C = r.reference_C;
    o.b0_window_s = r.b0_window_s;
    o.candidate_terms = r.terms;
    o.linear.errors = r.standard_errors;
    std::string invalid;
    if (!o.IsValid(&invalid)) throw InputError("auto: " + invalid);
    return FitAuto(runs, o);
  }
  PolyFitOptions o = name == "poly" ? PolyFitOptions{} : PresetOptions(name);
  o.channel = channel;
  if (name == "poly") {
    o.order = r.order.value_or(3);
    if (r.offset) o.offset = ParseOffset(*r.offset);
    o.terms = r.terms;
    o.extrapolate = r.beyond_range.value_or("hold") == "extrapolate";
  }
  if (r.reference_C) o.reference_C = r.reference_C;
  o.b0_window_s = r.b0_window_s;
  o.linear.errors = r.standard_errors;
  std::string invalid;
  if (!o.IsValid(&invalid)) throw InputError(fmt::format("{}: {}", name, invalid));
  return FitPoly(runs, o);
}

}  // namespace rlg::model
