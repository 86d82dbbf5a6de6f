#include "sim/import.h"

#include <charconv>
#include <cmath>
#include <filesystem>
#include <fmt/format.h>
#include <fstream>

#include "sim/csv.h"
#include "sim/errors.h"

namespace rlg::sim {

Run ImportTclab(const std::string& path, const TclabOptions& o) {
  std::ifstream in(path);
  if (!std::filesystem::is_regular_file(path) || !in) throw InputError(fmt::format("{}: cannot open TCLab log", path));
  Run run;
  run.id = std::filesystem::path(path).stem().string();
  run.source = path;
  if (const std::string why = RunIdProblem(run.id); !why.empty()) {
    throw InputError(fmt::format("{}: the file name gives the run id, but {}; rename the file", path, why));
  }
  const CsvReadOptions limits;  // what the tidy CSV it becomes can hold
  auto& T1 = run.AddColumn("T1");
  auto& T2 = run.AddColumn("T2");
  auto& P1 = run.AddColumn("P_heater1_W");
  auto& P2 = run.AddColumn("P_heater2_W");
  std::string line;
  int line_no = 0;
  double t_first = 0.0;
  while (std::getline(in, line)) {
    ++line_no;
    if (line_no == 1 && line.rfind("\xEF\xBB\xBF", 0) == 0) line.erase(0, 3);  // UTF-8 byte-order mark
    if (line.empty() || line == "\r") continue;
    double v[5];
    size_t start = 0;
    bool numeric = true;
    for (int f = 0; f < 5; ++f) {
      const size_t comma = line.find(',', start);
      if (comma == std::string::npos && f < 4) {
        throw InputError(fmt::format("{}:{}: expected at least 5 comma-separated fields (time, heater 1 %, heater 2 %, "
                                     "T1, T2)", path, line_no));
      }
      std::string field = line.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
      while (!field.empty() && (field.front() == ' ')) field.erase(field.begin());
      while (!field.empty() && (field.back() == ' ' || field.back() == '\r')) field.pop_back();
      const auto [ptr, ec] = std::from_chars(field.data(), field.data() + field.size(), v[f]);
      if (ec != std::errc() || ptr != field.data() + field.size() || !std::isfinite(v[f])) {
        numeric = false;
        if (run.t_s.empty() && line_no == 1) break;  // the header line
        throw InputError(fmt::format("{}:{}: field {}: expected a finite number, found '{}'", path, line_no, f + 1, field));
      }
      start = comma + 1;
    }
    if (!numeric) continue;
    if (run.t_s.empty()) t_first = v[0];
    const double t = v[0] - t_first;
    if (!run.t_s.empty() && !(t > run.t_s.back())) {
      throw InputError(fmt::format("{}:{}: time must increase ({} after {})", path, line_no, v[0], run.t_s.back() + t_first));
    }
    if (v[1] < 0.0 || v[1] > 100.0 || v[2] < 0.0 || v[2] > 100.0) {
      throw InputError(fmt::format("{}:{}: heater drive must be 0...100 %", path, line_no));
    }
    if (const std::string why = CsvRowReader::TimeProblem(t, limits); !why.empty()) {
      throw InputError(fmt::format("{}:{}: field 1: {}", path, line_no, why));
    }
    for (int f = 3; f < 5; ++f) {
      const std::string why = CsvRowReader::RangeProblem(CsvRowReader::RangeOf("T1", limits), v[f]);
      if (!why.empty()) throw InputError(fmt::format("{}:{}: field {}: {}", path, line_no, f + 1, why));
    }
    run.t_s.push_back(t);
    P1.push_back(v[1] * o.heater1_W_per_percent);
    P2.push_back(v[2] * o.heater2_W_per_percent);
    T1.push_back(v[3]);
    T2.push_back(v[4]);
  }
  if (run.t_s.size() < 2) throw InputError(fmt::format("{}: no data rows", path));
  return run;
}

}  // namespace rlg::sim
