// Verb export: a coefficient file's compensator as C code (compensation/c_export.h).

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "compensation/c_export.h"
#include "model/coefficients_json.h"
#include "sim/errors.h"
#include "tools/rlgtherm/commands.h"

namespace rlg::cli {

int RunExport(const ExportArgs& a) {
  compensation::CExportOptions options;
  options.precision = a.use_float ? compensation::CPrecision::kFloat : compensation::CPrecision::kDouble;
  options.prefix = a.prefix;
  options.source = a.coeffs;
  std::string error;
  if (!options.IsValid(&error)) throw InputError(error);
  const model::FittedModel m = model::ReadModelFile(a.coeffs);  // any model of the family
  const std::vector<std::string> written = compensation::WriteC(m, a.c_dir, options);
  const std::vector<std::string> channels = model::ModelChannels(m);
  std::vector<std::string> order;
  for (size_t i = 0; i < channels.size(); ++i) order.push_back(fmt::format("T_C[{}] = {}", i, channels[i]));
  fmt::print("{} as C99 ({}): {}\n  {}\n", model::ModelTitle(m), compensation::CPrecisionName(options.precision),
             fmt::join(written, ", "), fmt::join(order, ", "));
  return 0;
}

}  // namespace rlg::cli
