#pragma once
/// Writing with every step checked: a write that fails says why (disk full, file size limit,
/// I/O error), and the error's kind follows the cause. An output path the system refuses (no
/// such directory, not a directory, permission denied, read-only file system, a directory
/// where a file is wanted) is bad usage: InputError, exit status 2. A write that fails on a
/// usable path is neither usage nor input: OutputError, exit status 1. Errors name the path and
/// the operating system's reason.

#include <functional>
#include <iosfwd>
#include <memory>
#include <string>

namespace rlg::io {

/// True for errno values that mean the path itself is unusable (EACCES, ENOENT, EROFS, ...).
bool IsPathError(int err);
/// Throws "PATH: WHAT: REASON NOTE": InputError when IsPathError(err), else OutputError.
[[noreturn]] void ThrowOsError(const std::string& path, const std::string& what, int err, const char* note = "");

/// Writes a new file open on `fd` (the caller registered `file` for signal cleanup), then
/// fsyncs and closes it, every step checked; errors name `shown`, the path the user asked for,
/// followed by `note`. Removes `file` on failure. `write` may throw: the file is removed and
/// the exception passes on.
void WriteChecked(int fd, const std::string& file, const std::string& shown, const char* note,
                  const std::function<void(std::ostream&)>& write);
/// Writes to a descriptor that is not a file of ours (a device, a pipe, stdout by another name)
/// in place, every write checked; `close_fd` when the caller opened it. Partial output may have
/// gone out, as with any stream.
void WriteInPlace(int fd, bool close_fd, const std::string& shown, const std::function<void(std::ostream&)>& write);

/// Throws OutputError naming standard output and the reason if anything written to stdout
/// (std::cout or C stdio) has failed so far, e.g. `> /dev/full`. Flushes both first.
void CheckStdout();

/// A streambuf over a file descriptor that keeps the errno of its first failed write.
class FdOutBuf;
/// Standard output as a std::ostream straight onto descriptor 1 (stdio is flushed first), for
/// data: unlike C stdio, it keeps the reason of a failed write for the message.
class StdoutStream {
 public:
  StdoutStream();
  ~StdoutStream();
  StdoutStream(const StdoutStream&) = delete;
  StdoutStream& operator=(const StdoutStream&) = delete;
  std::ostream& stream() { return *stream_; }
  /// Flushes; OutputError naming standard output and the reason if any write failed.
  void Check();

 private:
  std::unique_ptr<FdOutBuf> buf_;
  std::unique_ptr<std::ostream> stream_;
};

}  // namespace rlg::io
