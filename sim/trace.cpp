#include "sim/trace.h"

#include <algorithm>

#include <cmath>
#include <fmt/format.h>

#include "sim/errors.h"

namespace rlg::sim {

std::string Run::Where() const {
  if (source.empty()) return fmt::format("run '{}'", id);
  if (first_line <= 0) return fmt::format("{}: run '{}'", source, id);
  return fmt::format("{}:{}: run '{}'", source, first_line, id);
}

int Run::Find(const std::string& name) const {
  for (size_t i = 0; i < names.size(); ++i)
    if (names[i] == name) return static_cast<int>(i);
  return -1;
}

const std::vector<double>& Run::Column(const std::string& name) const {
  const int i = Find(name);
  if (i < 0) throw InputError(fmt::format("{} has no column '{}'", Where(), name));
  return columns[i];
}

std::vector<double>& Run::AddColumn(const std::string& name) {
  names.push_back(name);
  columns.emplace_back();
  columns.back().reserve(t_s.capacity());
  return columns.back();
}

std::vector<const Run*> Trace::Select(const std::vector<std::string>& ids) const {
  std::vector<const Run*> out;
  for (const auto& id : ids) out.push_back(&FindRun(id));
  if (ids.empty())
    for (const auto& r : runs) out.push_back(&r);
  return out;
}

const Run& Trace::FindRun(const std::string& id) const {
  std::string ids;
  for (const auto& r : runs) {
    if (r.id == id) return r;
    ids += (ids.empty() ? "" : ", ") + r.id;
  }
  throw InputError(fmt::format("no run '{}' in {} (runs: {})", id, source.empty() ? "the data" : source, ids));
}

Run BlockMeans(const Run& run, double period_s) {
  Run out;
  out.id = run.id;
  out.source = run.source;
  out.first_line = run.first_line;
  for (const auto& n : run.names) out.AddColumn(n);
  size_t k = 0;
  while (k < run.size()) {
    const double start = run.t_s[k];
    size_t end = k;
    while (end < run.size() && run.t_s[end] < start + period_s) ++end;
    const double count = static_cast<double>(end - k);
    double t = 0.0;
    for (size_t i = k; i < end; ++i) t += run.t_s[i];
    out.t_s.push_back(t / count);
    for (size_t c = 0; c < run.columns.size(); ++c) {
      double sum = 0.0;
      for (size_t i = k; i < end; ++i) sum += run.columns[c][i];
      out.columns[c].push_back(sum / count);
    }
    k = end;
  }
  return out;
}

std::vector<Run> BlockAveraged(const std::vector<const Run*>& runs, double period_s) {
  std::vector<Run> out;
  for (const auto* r : runs) out.push_back(period_s > 0.0 ? BlockMeans(*r, period_s) : *r);
  return out;
}

std::vector<const Run*> Pointers(const std::vector<Run>& runs) {
  std::vector<const Run*> out;
  for (const auto& r : runs) out.push_back(&r);
  return out;
}

size_t FirstSampleAt(const Run& run, double since_start_s) {
  if (run.t_s.empty()) return 0;
  const double t = run.t_s.front() + since_start_s;
  return static_cast<size_t>(std::lower_bound(run.t_s.begin(), run.t_s.end(), t) - run.t_s.begin());
}

Run Head(const Run& run, size_t count) {
  Run out;
  out.id = run.id;
  out.source = run.source;
  out.first_line = run.first_line;
  count = std::min(count, run.size());
  out.t_s.assign(run.t_s.begin(), run.t_s.begin() + static_cast<std::ptrdiff_t>(count));
  for (size_t c = 0; c < run.names.size(); ++c) {
    out.AddColumn(run.names[c]).assign(run.columns[c].begin(), run.columns[c].begin() + static_cast<std::ptrdiff_t>(count));
  }
  return out;
}

Run Tail(const Run& run, size_t first) {
  Run out;
  out.id = run.id;
  out.source = run.source;
  first = std::min(first, run.size());
  out.first_line = run.first_line > 0 ? run.first_line + static_cast<int>(first) : 0;
  out.t_s.assign(run.t_s.begin() + static_cast<std::ptrdiff_t>(first), run.t_s.end());
  for (size_t c = 0; c < run.names.size(); ++c) {
    out.AddColumn(run.names[c]).assign(run.columns[c].begin() + static_cast<std::ptrdiff_t>(first), run.columns[c].end());
  }
  return out;
}

}  // namespace rlg::sim
