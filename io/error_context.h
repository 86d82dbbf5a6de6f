#pragma once
/// Refusals that name the data they are about. A library function that refuses bad data says
/// what is wrong; the caller that read the data knows the file (and the line of a run's first
/// row): these wrappers put that in front of the message, once.

#include <fmt/format.h>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "sim/errors.h"
#include "sim/trace.h"

namespace rlg::io {

/// Calls f(); an InputError or NumericalError whose message does not begin with `source` yet
/// gets `where` in front, so that every refusal about data names the file (and, for a run, the
/// line of its first row and the run).
template <typename F>
auto WithContext(const std::string& source, const std::string& where, F&& f) -> decltype(f()) {
  auto named = [&](const char* what) {
    return !source.empty() && std::string_view(what).rfind(source, 0) == 0 ? std::string(what)
                                                                           : fmt::format("{}: {}", where, what);
  };
  try {
    return f();
  } catch (const InputError& e) {
    throw InputError(named(e.what()));
  } catch (const NumericalError& e) {
    throw NumericalError(named(e.what()));
  }
}
/// WithContext for work on one run: run.Where() ("file:line: run 'id'").
template <typename F>
auto AtRun(const sim::Run& run, F&& f) -> decltype(f()) {
  return WithContext(run.source, run.Where(), std::forward<F>(f));
}
/// WithContext for work on a whole data file: its path.
template <typename F>
auto NamingFile(const std::string& path, F&& f) -> decltype(f()) {
  return WithContext(path, path, std::forward<F>(f));
}

/// `names` joined by `separator` for a message: the first `most`, then how many more ("a, b, c
/// and 65,000 more"), so that a header of thousands of columns gives a message of one line.
inline std::string ListForMessage(const std::vector<std::string>& names, std::string_view separator, size_t most = 20) {
  std::string out;
  for (size_t i = 0; i < names.size() && i < most; ++i) {
    if (i > 0) out += separator;
    out += names[i];
  }
  if (names.size() > most) out += fmt::format(" and {} more", names.size() - most);
  return out;
}

}  // namespace rlg::io
