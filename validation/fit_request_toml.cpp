#include "validation/fit_request_toml.h"

#include <array>

#include "model/poly_model.h"
#include "sim/errors.h"

namespace rlg::validation {

model::FitRequest ReadFitRequest(const io::TomlReader& t, const std::string& name_key) {
  model::FitRequest m;
  m.model = t.String(name_key, "guo2006");
  if (t.Has("pair")) {
    const auto p = t.Strings("pair");
    if (p.size() != 2) t.Fail("pair", "expected two channels, e.g. [\"T1\", \"T2\"]");
    m.pair = std::array<std::string, 2>{p[0], p[1]};
  }
  if (t.Has("method")) m.method = t.String("method");
  m.b0_window_s = t.Positive("b0_window_s", model::kB0Window_s);
  if (t.Has("channel")) m.channel = t.String("channel");
  if (t.Has("order")) m.order = static_cast<int>(t.Integer("order", 0));
  if (t.Has("terms")) {
    m.terms = t.Strings("terms");
    for (const auto& term : m.terms) {
      std::string why;
      if (term != "gradient" && !model::ParseTerm(term, m.channel.value_or("T1"), &why)) t.Fail("terms", why);
    }
  }
  if (t.Has("offset")) m.offset = t.String("offset");
  if (t.Has("reference_C")) m.reference_C = t.Number("reference_C");
  if (t.Has("beyond_range")) m.beyond_range = t.String("beyond_range");
  try {
    model::CheckFitRequest(m.model, m);
  } catch (const InputError& e) {
    t.FailHere(e.what());
  }
  return m;
}

}  // namespace rlg::validation
