#include "compensation/c_export.h"

#include <cctype>
#include <fmt/format.h>
#include <variant>

#include "compensation/c_export_eq2.h"
#include "compensation/c_export_poly.h"
#include "compensation/c_export_writer.h"
#include "io/atomic_output.h"
#include "sim/errors.h"

namespace rlg::compensation {
namespace {

constexpr size_t kMaxPrefix = 24;  // <prefix>_update then has C99's 31 significant characters

}  // namespace

const char* CPrecisionName(CPrecision p) { return p == CPrecision::kDouble ? "double" : "float"; }

bool CExportOptions::IsValid(std::string* error) const {
  auto fail = [&](const std::string& why) {
    if (error) *error = fmt::format("--prefix '{}': {}", prefix, why);
    return false;
  };
  if (prefix.empty()) return fail("expected a C identifier such as rlg_comp, found nothing");
  if (!std::isalpha(static_cast<unsigned char>(prefix[0]))) return fail("expected a C identifier starting with a letter");
  for (unsigned char ch : prefix)
    if (!(std::isalnum(ch) || ch == '_') || ch > 0x7e) return fail("expected a C identifier of letters, digits and '_'");
  if (prefix.back() == '_') return fail("must not end in '_' (the names append '_state', '_init', '_update')");
  if (prefix.size() > kMaxPrefix) {
    return fail(fmt::format("longer than {} characters ({}_update would pass the 31 characters C99 guarantees to tell "
                            "external names apart)",
                            kMaxPrefix, prefix));
  }
  return true;
}

CCode ExportC(const model::FittedModel& model, const CExportOptions& options) {
  std::string error;
  if (!options.IsValid(&error)) throw InputError(error);
  const c_export::Writer w(model, options);
  CCode code;
  code.header_name = options.prefix + ".h";
  code.source_name = options.prefix + ".c";
  if (const auto* eq2 = std::get_if<model::Guo2006Coefficients>(&model)) {
    code.header = c_export::Eq2Header(w, *eq2);
    code.source = c_export::Eq2Source(w, *eq2);
  } else {
    code.header = c_export::PolyHeader(w, std::get<model::PolyModel>(model));
    code.source = c_export::PolySource(w, std::get<model::PolyModel>(model));
  }
  return code;
}

std::vector<std::string> WriteC(const model::FittedModel& model, const std::string& dir, const CExportOptions& options) {
  const CCode code = ExportC(model, options);  // refuses bad options before DIR is touched
  io::OutputDirectory out(dir, io::OutputDirectory::Naming{"--c", "C code", "C file"});
  out.Write(code.header_name, [&](std::ostream& s) { s << code.header; });
  out.Write(code.source_name, [&](std::ostream& s) { s << code.source; });
  out.Commit();
  return {dir + "/" + code.header_name, dir + "/" + code.source_name};
}

}  // namespace rlg::compensation
