// libFuzzer harness: the coefficients JSON reader of every model (model::ParseModel, what
// `compensate --coeffs` reads; Eq. (2) files through model::ParseCoefficients as before).
// Properties, on every input:
//  - only InputError escapes (anything else is `rlgtherm: internal error`, exit 1);
//  - accepted coefficients compensate finite values anywhere in the data's limits (the corners
//    of the temperature range, the bias limit, the fastest rates), and survive writing and
//    reading back.

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "compensation/compensator.h"
#include "compensation/model_compensator.h"
#include "model/coefficients_json.h"
#include "sim/errors.h"
#include "sim/limits.h"
#include "tests/fuzz/fuzz_util.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace rlg;
  using namespace rlg::sim::limits;
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  model::FittedModel m;
  try {
    m = model::ParseModel(text, "fuzz.json");
  } catch (const InputError&) {
    return 0;
  }
  if (const auto* c = std::get_if<model::Guo2006Coefficients>(&m)) {
    for (const double Ti0 : {kMinTemperature_C, kMaxTemperature_C}) {
      compensation::Compensator comp(*c);
      fuzz::CheckFinite(comp.Update(0.0, Ti0, Ti0, kMaxAbsBias_dph), "compensated bias at power-on");
      for (const double Ti : {kMinTemperature_C, kMaxTemperature_C})
        for (const double Tj : {kMinTemperature_C, kMaxTemperature_C})
          fuzz::CheckFinite(comp.Update(c->b0_window_s + 1.0, Ti, Tj, -kMaxAbsBias_dph), "compensated bias");
    }
    const model::Guo2006Coefficients back = model::ParseCoefficients(model::ToJson(*c).dump(), "written.json");
    fuzz::Check(back.A == c->A && back.pair == c->pair && back.t10_range_C == c->t10_range_C, "JSON round trip");
    return 0;
  }
  const auto& p = std::get<model::PolyModel>(m);
  compensation::ModelCompensator comp(m);
  std::vector<double> T(comp.channels().size());
  double t = 0.0;
  for (int corner = 0; corner < 8; ++corner) {
    for (size_t c = 0; c < T.size(); ++c) T[c] = ((corner >> (c % 3)) & 1) ? kMaxTemperature_C : kMinTemperature_C;
    fuzz::CheckFinite(comp.Update(t, T.data(), corner % 2 ? kMaxAbsBias_dph : -kMaxAbsBias_dph), "compensated bias");
    t += kMinSamplePeriod_s;  // the whole temperature range in one shortest sample period
  }
  const model::FittedModel back = model::ParseModel(model::ToJson(p).dump(), "written.json");
  fuzz::Check(model::ToJson(std::get<model::PolyModel>(back)) == model::ToJson(p), "JSON round trip");
  return 0;
}
