#include "model/fit_model.h"

#include <fmt/format.h>

#include "io/error_context.h"
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
  const std::optional<PolyPreset> kind = ParsePolyPreset(name);
  if (!kind) throw InputError(fmt::format("model '{}': expected guo2006, poly, px4, ardupilot or auto", name));
  if (r.pair || r.method) throw InputError(fmt::format("pair and method are options of Eq. (2) (guo2006), not of {}", name));
  if (kind != PolyPreset::kPoly && r.order) {
    throw InputError(fmt::format("order: {} chooses its own; order is an option of poly", name));
  }
  const bool preset = kind == PolyPreset::kPx4 || kind == PolyPreset::kArduPilot;
  if (preset && r.offset) {
    throw InputError(fmt::format("offset: {}'s offset rule is part of it ({}); offset is an option of poly and auto", name,
                                 kind == PolyPreset::kPx4 ? "fitted" : "power_on"));
  }
  if (preset && !r.terms.empty()) {
    throw InputError(fmt::format("terms: {} is a cubic alone; for a cubic with terms fit poly with order 3", name));
  }
  if (r.offset) ParseOffset(*r.offset);
  for (const auto& t : r.terms) {  // read as the fit reads them, before any data ("gradient": every other channel)
    std::string why;
    if (t != "gradient" && !ParseTerm(t, r.channel.value_or("T1"), &why)) throw InputError(fmt::format("{}: {}", name, why));
  }
  if (r.beyond_range) {
    if (kind != PolyPreset::kPoly) {
      throw InputError(fmt::format("beyond_range: {} {}; beyond_range is an option of poly", name,
                                   kind == PolyPreset::kAuto ? "extrapolates (its search scored it beyond the range)" : "holds at the range's edge"));
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
    if (r.method) {
      const std::optional<Guo2006Method> method = ParseGuo2006Method(*r.method);
      if (!method) throw InputError(fmt::format("method '{}': expected joint or two_stage", *r.method));
      o.method = *method;
    }
    o.b0_window_s = r.b0_window_s;
    return FitGuo2006(runs, o);
  }
  const std::string channel = r.channel.value_or("T1");
  const PolyPreset kind = *ParsePolyPreset(name);  // CheckFitRequest refused any other name
  if (kind == PolyPreset::kAuto) {
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
  PolyFitOptions o = kind == PolyPreset::kPoly ? PolyFitOptions{} : PresetOptions(kind);
  o.channel = channel;
  if (kind == PolyPreset::kPoly) {
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

FittedModel FitRequested(const std::vector<const sim::Run*>& runs, const FitRequest& request, double average_s,
                         const std::string& source) {
  std::vector<const sim::Run*> fitted = runs;
  std::vector<sim::Run> averaged;
  if (average_s > 0.0) {
    averaged = sim::BlockAveraged(runs, average_s);
    fitted = sim::Pointers(averaged);
  }
  CheckFitRequest(ResolveModelName(request, fitted), request);
  auto fit = [&] { return FitModel(fitted, request); };
  return source.empty() ? fit() : io::NamingFile(source, fit);
}

}  // namespace rlg::model
