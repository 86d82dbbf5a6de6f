#include "io/checked_stream.h"

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fmt/format.h>
#include <iostream>
#include <memory>
#include <streambuf>
#include <unistd.h>

#include "sim/errors.h"

namespace rlg::io {


// Errors of the path itself (the user named somewhere the system will not let us write) as
/// opposed to failures of the writing (disk full, file size limit, I/O error).
bool IsPathError(int err) {
  switch (err) {
    case EACCES: case EPERM: case EROFS: case ENOTDIR: case ENOENT: case EISDIR: case ENAMETOOLONG: case ELOOP:
    case EEXIST: case ENOTEMPTY: case EBADF:  // EBADF: -o /dev/fd/N with N not open
      return true;
    default:
      return false;
  }
}

[[noreturn]] void ThrowOsError(const std::string& path, const std::string& what, int err, const char* note) {
  const std::string message = fmt::format("{}: {}: {}{}", path, what, std::strerror(err), note);
  if (IsPathError(err)) throw InputError(message);
  throw OutputError(message);
}

/// A streambuf over a file descriptor that keeps the errno of the first failed write: iostreams
/// only say that something failed, and a message must say why (disk full, file too large).
class FdOutBuf : public std::streambuf {
 public:
  explicit FdOutBuf(int fd) : fd_(fd) { setp(buf_, buf_ + sizeof buf_); }
  int error() const { return error_; }

 protected:
  int_type overflow(int_type ch) override {
    if (!Drain()) return traits_type::eof();
    if (!traits_type::eq_int_type(ch, traits_type::eof())) {
      *pptr() = traits_type::to_char_type(ch);
      pbump(1);
    }
    return traits_type::not_eof(ch);
  }
  int sync() override { return Drain() ? 0 : -1; }

 private:
  bool Drain() {
    if (error_ != 0) return false;
    const char* p = pbase();
    while (p < pptr()) {
      const ssize_t n = ::write(fd_, p, static_cast<size_t>(pptr() - p));
      if (n < 0 && errno == EINTR) continue;
      if (n < 0) {
        error_ = errno;
        return false;
      }
      p += n;
    }
    setp(buf_, buf_ + sizeof buf_);
    return true;
  }
  int fd_;
  int error_ = 0;
  char buf_[1 << 16];
};

/// Writes a new file at `file` (registered for signal cleanup by the caller), every step
/// checked; errors name `shown`, the path the user asked for. Removes `file` on failure.
void WriteChecked(int fd, const std::string& file, const std::string& shown, const char* note,
                  const std::function<void(std::ostream&)>& write) {
  auto fail = [&](int err) {
    ::close(fd);
    ::unlink(file.c_str());
    ThrowOsError(shown, "writing failed", err, note);
  };
  {
    FdOutBuf buf(fd);
    std::ostream out(&buf);
    try {
      write(out);
    } catch (...) {
      ::close(fd);
      ::unlink(file.c_str());
      throw;
    }
    out.flush();
    if (buf.error() != 0) fail(buf.error());
    if (!out) fail(EIO);  // a writer that set the stream's state itself
  }
  // fsync: errors a file system reports late (delayed allocation, NFS) surface here, and the
  // renamed file is not an empty shell after a power cut.
  if (::fsync(fd) != 0) {
    const int err = errno;
    fail(err);
  }
  if (::close(fd) != 0) {
    const int err = errno;
    ::unlink(file.c_str());
    ThrowOsError(shown, "writing failed", err, note);
  }
}

/// Writes to a descriptor that is not a file of ours (a device, a pipe, stdout by another name):
/// in place, every write checked; `close_fd` when we opened it. Partial output may have gone
/// out, as with any stream, so the message does not claim otherwise.
void WriteInPlace(int fd, bool close_fd, const std::string& shown, const std::function<void(std::ostream&)>& write) {
  int err = 0;
  {
    FdOutBuf buf(fd);
    std::ostream out(&buf);
    try {
      write(out);
    } catch (...) {
      if (close_fd) ::close(fd);
      throw;
    }
    out.flush();
    err = buf.error() != 0 ? buf.error() : (out ? 0 : EIO);
  }
  if (close_fd && ::close(fd) != 0 && err == 0) err = errno;
  if (err != 0) ThrowOsError(shown, "writing failed", err);
}

void CheckStdout() {
  errno = 0;
  std::cout.flush();
  const bool flushed = std::fflush(stdout) == 0;
  const int err = errno;
  if (flushed && std::cout && !std::ferror(stdout)) return;
  // C stdio drops a buffer it failed to write, and with it the reason, when the failure came
  // before this final flush (more than a buffer of output).
  throw OutputError(fmt::format("standard output: writing failed: {}",
                                err != 0 ? std::strerror(err) : "part of the output was lost"));
}

StdoutStream::StdoutStream() {
  CheckStdout();  // what stdio holds goes out first
  buf_ = std::make_unique<FdOutBuf>(STDOUT_FILENO);
  stream_ = std::make_unique<std::ostream>(buf_.get());
}

StdoutStream::~StdoutStream() { stream_->flush(); }  // errors: see Check

void StdoutStream::Check() {
  stream_->flush();
  if (buf_->error() != 0) throw OutputError(fmt::format("standard output: writing failed: {}", std::strerror(buf_->error())));
}

}  // namespace rlg::io
