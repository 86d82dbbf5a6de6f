#pragma once
/// Whether a path names a regular file, for the readers' "not found" errors: never throws. A
/// path the system cannot even look up (a name too long, a loop of symbolic links) names no
/// file to read, so the reader's own InputError names it with the file and line that gave it;
/// std::filesystem::is_regular_file(path) would throw filesystem_error instead (fuzz_scenario
/// found a 1,000-character gyro name ending the process so).

#include <filesystem>
#include <system_error>

namespace rlg::io {

inline bool IsRegularFile(const std::filesystem::path& path) {
  std::error_code ec;
  return std::filesystem::is_regular_file(path, ec);
}

}  // namespace rlg::io
