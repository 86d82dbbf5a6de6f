// Verb export: a coefficient file's compensator as C code (compensation/c_export.h).

#include <CLI/CLI.hpp>
#include <fmt/format.h>
#include <fmt/ranges.h>
#include <memory>

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

Verb RegisterExport(CLI::App& app) {
  auto a = std::make_shared<ExportArgs>();
  CLI::App* cmd = app.add_subcommand("export",
                                     "write a coefficient file's compensator as C99 code for the gyro's "
                                     "processor (docs/firmware.md)");
  cmd->add_option("COEFFS", a->coeffs, "coefficients JSON from 'fit' (any model)")->required();
  cmd->add_option("--c", a->c_dir,
                  "directory for <prefix>.h and <prefix>.c (created if missing; files of "
                  "other names in it are left alone)")
      ->required();
  auto* as_float = cmd->add_flag("--float", a->use_float, "float arithmetic (for an FPU without double)");
  auto* as_double = cmd->add_flag("--double", "double arithmetic (the default)");
  as_float->excludes(as_double);
  cmd->add_option("--prefix", a->prefix,
                  "the files' stem and the names' prefix: <prefix>_state, "
                  "<prefix>_init, <prefix>_update")
      ->capture_default_str();
  return {cmd, [a] { return RunExport(*a); }};
}

}  // namespace rlg::cli
