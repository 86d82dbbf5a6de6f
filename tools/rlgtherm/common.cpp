#include "tools/rlgtherm/common.h"

#include <fmt/format.h>
#include <iostream>

#include "sim/errors.h"

namespace rlg::cli {

sim::Trace LoadData(const std::string& path, bool require_bias, const std::vector<std::string>& keep) {
  io::CsvReadOptions o;
  o.require_bias = require_bias;
  o.keep_columns = keep;
  io::CsvReadResult r = path == "-" ? io::ReadTraceCsv(std::cin, "<stdin>", o) : io::ReadTraceCsv(path, o);
  for (const auto& w : r.warnings) fmt::print(stderr, "rlgtherm: warning: {}\n", w);
  return std::move(r.trace);
}

void WriteText(const std::string& path, const std::string& text) {
  io::WriteFileAtomically(path, [&](std::ostream& out) { out << text; });
}

std::array<std::string, 2> ParsePair(const std::string& text) {
  const auto comma = text.find(',');
  if (comma == std::string::npos || text.find(',', comma + 1) != std::string::npos || comma == 0 ||
      comma + 1 == text.size()) {
    throw InputError(fmt::format("--pair '{}': expected two channels separated by a comma, e.g. T1,T2", text));
  }
  return {text.substr(0, comma), text.substr(comma + 1)};
}

}  // namespace rlg::cli
