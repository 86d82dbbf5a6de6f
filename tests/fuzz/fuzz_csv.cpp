// libFuzzer harness: the tidy CSV reader (io::ReadTraceCsv on a stream) and what the CLI does
// with what it accepts. Properties, on every input:
//  - only InputError escapes the reader (anything else is `rlgtherm: internal error`, exit 1);
//  - an accepted trace is within the reader's limits (FindUnreadableValue agrees), and written
//    back with WriteTraceCsv it reads again to the same runs and values: the writer never writes
//    what the reader refuses;
//  - `allan`'s read-offs and `compensate`'s numbers (fixed coefficients) on it are finite, or
//    the run is refused with InputError: no inf or NaN is ever printed or written.

#include <cstddef>
#include <cstdint>
#include <sstream>
#include <string>

#include "compensation/compensator.h"
#include "compensation/evaluation.h"
#include "io/csv.h"
#include "model/allan.h"
#include "model/guo2006.h"
#include "sim/errors.h"
#include "tests/fuzz/fuzz_util.h"

namespace rlg::fuzz {
namespace {

/// Writer's precision (io/csv.cpp): 4 decimals for temperatures, 6 otherwise: half a unit.
double WriteTolerance(const std::string& name) { return name[0] == 'T' ? 5e-5 : 5e-7; }

void CheckRoundTrip(const sim::Trace& trace) {
  std::istringstream in(io::FormatTraceCsv(trace));
  io::CsvReadOptions options;
  options.require_bias = false;
  io::CsvReadResult back;
  try {
    back = io::ReadTraceCsv(in, "written.csv", options);
  } catch (const InputError& e) {
    Check(false, std::string("the reader refuses what the writer wrote: ") + e.what());
  }
  Check(back.trace.runs.size() == trace.runs.size(), "run count changed on the round trip");
  for (size_t r = 0; r < trace.runs.size(); ++r) {
    const sim::Run &a = trace.runs[r], &b = back.trace.runs[r];
    Check(a.id == b.id && a.names == b.names && a.t_s == b.t_s, "run '" + a.id + "' changed on the round trip");
    for (size_t c = 0; c < a.names.size(); ++c) {
      for (size_t k = 0; k < a.size(); ++k) {
        Check(std::abs(a.columns[c][k] - b.columns[c][k]) <= WriteTolerance(a.names[c]) * (1.0 + 1e-9),
              "value of '" + a.names[c] + "' changed on the round trip");
      }
    }
  }
}

void CheckAllan(const sim::Run& run) {
  if (!run.Has("bias_dph") || run.size() < 18) return;  // what `allan` refuses
  const model::AllanCurve curve = model::OverlappingAllan(run.Column("bias_dph"), run.MeanSamplePeriod());
  for (size_t i = 0; i < curve.tau_s.size(); ++i) {
    CheckFinite(curve.tau_s[i], "Allan tau");
    CheckFinite(curve.adev[i], "Allan deviation");
  }
  const model::NoiseReadOffs r = model::ReadNoiseTerms(curve);
  for (const auto& term : r.terms) {
    CheckFinite(term.resolved ? term.value : term.upper_bound, "Allan read-off");
    Check(term.resolved || !term.reason.empty(), "an unresolved Allan term without a reason");
  }
}

void CheckCompensation(const sim::Run& run) {
  if (!run.Has("bias_dph") || !run.Has("T1") || !run.Has("T2")) return;
  model::Guo2006Coefficients c;  // the magnitudes of a fit on the default gyro
  c.A << 0.006, 1e-4, -1e-6, -8e-5, 1e-6, 1e-8, 0.45, -1e-3, 1e-5;
  c.t10_range_C = {-30.0, 60.0};
  try {
    const std::vector<double> out = compensation::CompensateRun(c, run);
    for (double v : out) CheckFinite(v, "compensated bias");
    const compensation::RunEvaluation e = compensation::EvaluateRun(run, out, c);  // compensate's defaults
    for (double v : {e.bias_before_dph, e.bias_after_dph, e.stability_before.sigma, e.stability_after.sigma,
                     e.stability_100s_before.sigma, e.stability_100s_after.sigma, e.stability_before.averaging_s,
                     e.stability_100s_before.averaging_s, e.trend_dph_per_C, e.b0_error_dph}) {
      CheckFinite(v, "compensate's Table 2 number");
    }
    // EvaluateRun's "no trend can be estimated" (fewer than three 100 s blocks, no temperature
    // change, or none between the run's halves): an infinite error, which compensate prints as
    // ±inf and JSON null (reported; compensation/evaluation.cpp's to change). Never NaN.
    Check(e.trend_stderr_dph_per_C >= 0.0, "trend error is NaN or negative");
  } catch (const InputError&) {
    // A refusal is a correct answer (a run too short for the window or the stability blocks).
  }
}

}  // namespace
}  // namespace rlg::fuzz

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace rlg;
  std::istringstream in(std::string(reinterpret_cast<const char*>(data), size));
  io::CsvReadOptions options;
  options.require_bias = false;  // thermal-only data is valid too (diagnose)
  io::CsvReadResult result;
  try {
    result = io::ReadTraceCsv(in, "fuzz.csv", options);
  } catch (const InputError&) {
    return 0;
  }
  for (const auto& run : result.trace.runs) {
    fuzz::Check(sim::FindUnreadableValue(run, options).empty(), "accepted a value beyond the limits in run " + run.id);
    fuzz::CheckAllan(run);
    fuzz::CheckCompensation(run);
  }
  fuzz::CheckRoundTrip(result.trace);
  return 0;
}
