#pragma once
/// Fitting any member of the model family (model/compensation_model.h) by name, with the options
/// `rlgtherm fit` and the Python module's fit() share:
///
///   guo2006    Eq. (2) for a sensor pair (FitGuo2006: pair, method, B0 window)
///   poly       a polynomial in one channel (FitPoly: channel, order, terms, offset, reference,
///              beyond_range)
///   px4        poly's PX4 preset (channel, reference)
///   ardupilot  poly's ArduPilot preset (channel, reference)
///   auto       the polynomial selected by FitAuto (channel, candidate terms, offset, reference); it
///              extrapolates beyond its range
///
/// Without a name: guo2006 where every run has both channels of the pair (or a pair is given),
/// else poly. An option that the named model does not take is refused (InputError), so that
/// nothing asked for is silently ignored.

#include <array>
#include <optional>
#include <string>
#include <vector>

#include "model/b0_window.h"
#include "model/compensation_model.h"
#include "sim/trace.h"

namespace rlg::model {

struct FitRequest {
  std::string model;  ///< empty: the rule above
  std::optional<std::array<std::string, 2>> pair;
  std::optional<std::string> method;  ///< guo2006: "joint" (default) or "two_stage"
  double b0_window_s = kB0Window_s;
  std::optional<std::string> channel;
  std::optional<int> order;
  std::vector<std::string> terms;
  std::optional<std::string> offset;  ///< "fitted" or "power_on"
  std::optional<double> reference_C;
  std::optional<std::string> beyond_range;  ///< poly: "hold" (default) or "extrapolate"
  /// The polynomials' cluster-robust standard errors (false: the coefficients alone, for a
  /// plan's Monte Carlo, which never reads them).
  bool standard_errors = true;
};

/// The model a request names, by the rule above.
std::string ResolveModelName(const FitRequest& request, const std::vector<const sim::Run*>& runs);

/// InputError for an unknown model `name`, an option it does not take or a term it cannot read
/// (CheckFitRequest needs no data: a command line or a plan file checks it before reading any).
void CheckFitRequest(const std::string& name, const FitRequest& request);

/// The fit. InputError for an unknown model, option or value; the fits' own errors otherwise.
FittedModel FitModel(const std::vector<const sim::Run*>& runs, const FitRequest& request);

/// The fit `rlgtherm fit` and the Python module's fit() make of a request: on `runs` as means
/// over `average_s` seconds when positive (sim::BlockAveraged), the request checked first
/// (CheckFitRequest on the model ResolveModelName names: a usage error before any fit), and a
/// refusal about the data naming `source`, the file the runs were read from (empty: none).
FittedModel FitRequested(const std::vector<const sim::Run*>& runs, const FitRequest& request, double average_s,
                         const std::string& source);

}  // namespace rlg::model
