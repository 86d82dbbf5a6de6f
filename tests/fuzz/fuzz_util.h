#pragma once
// Shared by the libFuzzer harnesses (tests/fuzz/README.md): a property that fails aborts with a
// message, so libFuzzer saves the input as a crash; a private directory for loaders that take
// paths.

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <unistd.h>

namespace rlg::fuzz {

/// Fails the run (libFuzzer keeps the input) when `ok` is false.
inline void Check(bool ok, const std::string& what) {
  if (ok) return;
  std::fprintf(stderr, "fuzz property violated: %s\n", what.c_str());
  std::abort();
}

inline void CheckFinite(double v, const std::string& what) { Check(std::isfinite(v), what + " is not finite"); }

/// A directory of this process's own, removed at exit: in /dev/shm (memory) where it exists,
/// else under $TMPDIR. Each input is written to a file there, and a file rewritten on a disk file
/// system costs the kernel more than the harness's own work (ext4 frees and discards its blocks
/// at each truncation: 230 inputs a second for fuzz_gyro in /tmp, 2,700 in /dev/shm, measured
/// side by side on the sanitizer build).
class ScratchDir {
 public:
  ScratchDir() {
    std::error_code ec;
    const std::filesystem::path shm = "/dev/shm";
    const std::filesystem::path base = std::filesystem::is_directory(shm, ec) && ::access("/dev/shm", W_OK) == 0
                                           ? shm
                                           : std::filesystem::temp_directory_path();
    std::string pattern = (base / "rlg_fuzz_XXXXXX").string();
    Check(::mkdtemp(pattern.data()) != nullptr, "mkdtemp");
    path_ = pattern;
  }
  ~ScratchDir() {
    std::error_code ignored;
    std::filesystem::remove_all(path_, ignored);
  }
  /// Writes `text` to `name` in the directory and returns its path.
  std::string Write(const std::string& name, const std::string& text) const {
    const std::string p = (path_ / name).string();
    std::ofstream out(p, std::ios::binary | std::ios::trunc);
    out.write(text.data(), static_cast<std::streamsize>(text.size()));
    Check(static_cast<bool>(out), "writing " + p);
    return p;
  }
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

}  // namespace rlg::fuzz
