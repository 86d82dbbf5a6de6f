// libFuzzer harness: the coefficients JSON reader (model::ParseCoefficients, what `compensate
// --coeffs` reads). Properties, on every input:
//  - only InputError escapes (anything else is `rlgtherm: internal error`, exit 1);
//  - accepted coefficients compensate finite values anywhere in the data's limits (the corners
//    of the temperature range, the bias limit), and survive ToJson -> ParseCoefficients.

#include <cstddef>
#include <cstdint>
#include <string>

#include "compensation/compensator.h"
#include "model/coefficients_json.h"
#include "sim/errors.h"
#include "sim/limits.h"
#include "tests/fuzz/fuzz_util.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace rlg;
  using namespace rlg::sim::limits;
  model::Guo2006Coefficients c;
  try {
    c = model::ParseCoefficients(std::string_view(reinterpret_cast<const char*>(data), size), "fuzz.json");
  } catch (const InputError&) {
    return 0;
  }
  for (const double Ti0 : {kMinTemperature_C, kMaxTemperature_C}) {
    compensation::Compensator comp(c);
    fuzz::CheckFinite(comp.Update(0.0, Ti0, Ti0, kMaxAbsBias_dph), "compensated bias at power-on");
    for (const double Ti : {kMinTemperature_C, kMaxTemperature_C})
      for (const double Tj : {kMinTemperature_C, kMaxTemperature_C})
        fuzz::CheckFinite(comp.Update(c.b0_window_s + 1.0, Ti, Tj, -kMaxAbsBias_dph), "compensated bias");
  }
  const model::Guo2006Coefficients back = model::ParseCoefficients(model::ToJson(c).dump(), "written.json");
  fuzz::Check(back.A == c.A && back.pair == c.pair && back.t10_range_C == c.t10_range_C, "JSON round trip");
  return 0;
}
