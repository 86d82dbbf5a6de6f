#include "sim/output_file.h"

#include <atomic>
#include <cerrno>
#include <climits>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <fcntl.h>
#include <fmt/format.h>
#include <iostream>
#include <memory>
#include <streambuf>
#include <sys/stat.h>
#include <unistd.h>

#include "sim/errors.h"

namespace rlg::sim {

namespace {

// ---- errors ---------------------------------------------------------------------------------

/// Errors of the path itself (the user named somewhere the system will not let us write) as
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

/// What a failed output leaves: nothing (a file or a report is whole or absent).
const char* const kNoFile = " (nothing written)";

/// "PATH: WHAT: REASON NOTE", InputError or OutputError by the kind of error.
[[noreturn]] void ThrowOsError(const std::string& path, const std::string& what, int err, const char* note = "") {
  const std::string message = fmt::format("{}: {}: {}{}", path, what, std::strerror(err), note);
  if (IsPathError(err)) throw InputError(message);
  throw OutputError(message);
}

// ---- signal cleanup -------------------------------------------------------------------------

/// Registered temporaries. The handler only reads slots whose state is kLive; a slot is filled
/// while kBusy, so that a signal arriving during (un)registration never sees half a path.
// A report holds a handful of files; --plot two figures per run (validate: per run and
// compensator): 256 slots (1 MiB of paths) leave room for ~120 runs in one figure directory.
constexpr int kSlots = 256;
enum SlotState : int { kFree = 0, kBusy = 1, kLive = 2 };
struct Slot {
  std::atomic<int> state{kFree};
  unsigned long seq = 0;  // registration order: the handler removes the newest first
  bool is_dir = false;
  char path[PATH_MAX] = {};
};
static_assert(std::atomic<int>::is_always_lock_free, "the signal handler reads slot states");
Slot g_slots[kSlots];
unsigned long g_next_seq = 1;
const int kCleanupSignals[] = {SIGINT, SIGTERM, SIGHUP};

extern "C" void CleanupAndReraise(int sig) {
  // Only async-signal-safe calls here: unlink, rmdir, raise.
  unsigned long below = ULONG_MAX;
  while (true) {
    int newest = -1;
    for (int i = 0; i < kSlots; ++i) {
      if (g_slots[i].state.load() == kLive && g_slots[i].seq < below &&
          (newest < 0 || g_slots[i].seq > g_slots[newest].seq)) {
        newest = i;
      }
    }
    if (newest < 0) break;
    below = g_slots[newest].seq;
    if (g_slots[newest].is_dir) {
      ::rmdir(g_slots[newest].path);
    } else {
      ::unlink(g_slots[newest].path);
    }
  }
  // SA_RESETHAND restored the default action; the signal stays blocked until this handler
  // returns, and is then delivered again and ends the process as "killed by signal".
  ::raise(sig);
}

/// Holds back the cleanup signals in a scope (a commit that must not stop half-way).
class SignalHold {
 public:
  SignalHold() {
    sigset_t set;
    sigemptyset(&set);
    for (int s : kCleanupSignals) sigaddset(&set, s);
    sigprocmask(SIG_BLOCK, &set, &old_);
  }
  ~SignalHold() { sigprocmask(SIG_SETMASK, &old_, nullptr); }
  SignalHold(const SignalHold&) = delete;
  SignalHold& operator=(const SignalHold&) = delete;

 private:
  sigset_t old_;
};

}  // namespace

// ---- checked writing ------------------------------------------------------------------------

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

namespace {

/// Creates `path` exclusively, registered for the signal handler before it exists (so that no
/// signal can leave it behind). A name taken already (the partial file of a dead process that
/// had our pid) gets a counter appended. Returns the descriptor; `path` is the name used.
int CreateExclusive(std::string& path, std::unique_ptr<TempRegistration>& registration, const std::string& shown) {
  const std::string base = path;
  for (int attempt = 0;; ++attempt) {
    if (attempt > 0) path = fmt::format("{}-{}", base, attempt);
    registration = std::make_unique<TempRegistration>(path);
    const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
    if (fd >= 0) return fd;
    const int err = errno;
    registration.reset();
    if (err != EEXIST || attempt == 99) ThrowOsError(shown, "cannot create the output file", err);
  }
}

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

/// The descriptor a path names by itself ("/dev/stdout", "/dev/stderr", "/dev/fd/N",
/// "/proc/self/fd/N"), or -1. Written as that descriptor: a temporary beside "/dev/stdout"
/// would be a file in /dev, and the rename would replace the link.
int DescriptorAlias(const std::string& path) {
  if (path == "/dev/stdout") return STDOUT_FILENO;
  if (path == "/dev/stderr") return STDERR_FILENO;
  for (const char* prefix : {"/dev/fd/", "/proc/self/fd/"}) {
    const std::string p = prefix;
    if (path.size() > p.size() && path.compare(0, p.size(), p) == 0 &&
        path.find_first_not_of("0123456789", p.size()) == std::string::npos && path.size() - p.size() < 6) {
      return std::stoi(path.substr(p.size()));
    }
  }
  return -1;
}

std::string Dirname(const std::string& path) {
  const auto slash = path.find_last_of('/');
  if (slash == std::string::npos) return ".";
  return slash == 0 ? "/" : path.substr(0, slash);
}

std::string Basename(const std::string& path) {
  const auto slash = path.find_last_of('/');
  return slash == std::string::npos ? path : path.substr(slash + 1);
}

/// Best effort: makes a rename durable. Not every file system supports fsync on a directory,
/// and the file itself is already whole, so a failure here is not reported.
void SyncDirectory(const std::string& dir) {
  const int fd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd < 0) return;
  ::fsync(fd);
  ::close(fd);
}

std::string StripTrailingSlashes(std::string p) {
  while (p.size() > 1 && p.back() == '/') p.pop_back();
  return p;
}

}  // namespace

// ---- public ---------------------------------------------------------------------------------

TempRegistration::TempRegistration(const std::string& path, bool is_dir) : slot_(-1) {
  if (path.size() >= PATH_MAX) ThrowOsError(path, "cannot create the output file", ENAMETOOLONG);
  for (int i = 0; i < kSlots; ++i) {
    int expected = kFree;
    if (g_slots[i].state.compare_exchange_strong(expected, kBusy)) {
      slot_ = i;
      break;
    }
  }
  if (slot_ < 0) throw std::logic_error(fmt::format("TempRegistration: more than {} temporaries at once", kSlots));
  Slot& s = g_slots[slot_];
  std::memcpy(s.path, path.c_str(), path.size() + 1);
  s.is_dir = is_dir;
  s.seq = g_next_seq++;
  s.state.store(kLive);
}

TempRegistration::~TempRegistration() { g_slots[slot_].state.store(kFree); }

void InstallSignalCleanup() {
  for (int sig : kCleanupSignals) {
    struct sigaction old {};
    if (sigaction(sig, nullptr, &old) != 0 || old.sa_handler == SIG_IGN) continue;
    struct sigaction sa {};
    sa.sa_handler = CleanupAndReraise;
    sigemptyset(&sa.sa_mask);
    for (int s : kCleanupSignals) sigaddset(&sa.sa_mask, s);  // one cleanup at a time
    sa.sa_flags = SA_RESETHAND;
    sigaction(sig, &sa, nullptr);
  }
}

std::string PartialName(const std::string& path) {
  const std::string dir = Dirname(path);
  const std::string name = fmt::format(".{}.rlgtherm-partial-{}", Basename(path), ::getpid());
  return path.find('/') == std::string::npos ? name : (dir == "/" ? "/" : dir + "/") + name;
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

void WriteFileAtomically(const std::string& path, const std::function<void(std::ostream&)>& write) {
  if (path == "-") {
    StdoutStream out;
    write(out.stream());
    out.Check();
    return;
  }
  if (const int fd = DescriptorAlias(path); fd >= 0) {
    CheckStdout();  // what stdio holds goes out first
    WriteInPlace(fd, /*close_fd=*/false, path, write);
    return;
  }
  struct stat st {};
  const bool exists = ::stat(path.c_str(), &st) == 0;
  if (path.empty() || path.back() == '/' || (exists && S_ISDIR(st.st_mode))) {
    ThrowOsError(path, "cannot write the output file there", EISDIR);
  }
  if (exists && !S_ISREG(st.st_mode)) {
    // A device or a FIFO (-o /dev/null, a named pipe): written in place. Renaming a temporary
    // onto it would replace the node with a regular file (as root, /dev/null itself).
    const int fd = ::open(path.c_str(), O_WRONLY | O_CLOEXEC);
    if (fd < 0) {
      const int err = errno;
      ThrowOsError(path, "cannot open the output", err);
    }
    WriteInPlace(fd, /*close_fd=*/true, path, write);
    return;
  }
  std::string tmp = PartialName(path);
  std::unique_ptr<TempRegistration> registration;
  const int fd = CreateExclusive(tmp, registration, path);
  WriteChecked(fd, tmp, path, kNoFile, write);
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    const int err = errno;
    ::unlink(tmp.c_str());
    ThrowOsError(path, "cannot move the finished file into place", err, kNoFile);
  }
  SyncDirectory(Dirname(path));
}

// ---- OutputDirectory ------------------------------------------------------------------------

OutputDirectory::OutputDirectory(std::string dir, Naming naming)
    : dir_(StripTrailingSlashes(std::move(dir))), naming_(std::move(naming)) {
  if (dir_.empty()) throw InputError(fmt::format("{}: empty directory name", naming_.option));
  const std::string write_there = fmt::format("cannot write the {} there", naming_.noun);
  const std::string create = fmt::format("cannot create the {} directory", naming_.noun);
  auto& regs = registrations_;
  // The destructor does not run when the constructor throws: undo by hand.
  auto fail = [&](const std::string& what, int err) {
    for (auto it = created_parents_.rbegin(); it != created_parents_.rend(); ++it) ::rmdir(it->c_str());
    regs.clear();
    ThrowOsError(dir_, what, err);
  };
  struct stat st {};
  if (::stat(dir_.c_str(), &st) == 0) {
    if (!S_ISDIR(st.st_mode)) ThrowOsError(dir_, write_there, ENOTDIR);
    dir_existed_ = true;
    staging_ = fmt::format("{}/.rlgtherm-partial-{}", dir_, ::getpid());
  } else if (const int err = errno; err != ENOENT && err != ENOTDIR) {
    ThrowOsError(dir_, write_there, err);
  } else {  // ENOTDIR: a parent is a file, named below
    // Create the missing parents (as mkdir -p), remembering them to remove them again.
    std::vector<std::string> missing;
    for (std::string p = Dirname(dir_); p != "/" && p != "."; p = Dirname(p)) {
      if (::stat(p.c_str(), &st) == 0) {
        if (!S_ISDIR(st.st_mode)) ThrowOsError(dir_, fmt::format("{} ('{}' is a file)", create, p), ENOTDIR);
        break;
      }
      if (const int err = errno; err != ENOENT && err != ENOTDIR) ThrowOsError(dir_, create, err);
      missing.push_back(p);
    }
    for (auto it = missing.rbegin(); it != missing.rend(); ++it) {
      regs.push_back(std::make_unique<TempRegistration>(*it, /*is_dir=*/true));
      if (::mkdir(it->c_str(), 0777) != 0) {
        const int err = errno;
        fail(fmt::format("{} ('{}')", create, *it), err);
      }
      created_parents_.push_back(*it);
    }
    staging_ = PartialName(dir_);
  }
  const std::string base = staging_;
  for (int attempt = 0;; ++attempt) {
    if (attempt > 0) staging_ = fmt::format("{}-{}", base, attempt);
    regs.push_back(std::make_unique<TempRegistration>(staging_, /*is_dir=*/true));
    if (::mkdir(staging_.c_str(), 0777) == 0) break;
    const int err = errno;
    regs.pop_back();
    if (err != EEXIST || attempt == 99) {
      fail(dir_existed_ ? write_there : create, err);
    }
  }
}

OutputDirectory::~OutputDirectory() {
  if (!committed_) {
    for (const auto& n : names_) ::unlink((staging_ + "/" + n).c_str());
    ::rmdir(staging_.c_str());
    for (auto it = created_parents_.rbegin(); it != created_parents_.rend(); ++it) ::rmdir(it->c_str());
  }
}

std::string OutputDirectory::NothingWritten() const { return fmt::format(" (no {} written)", naming_.noun); }

std::string OutputDirectory::Stage(const std::string& name) {
  if (name.empty() || name.find('/') != std::string::npos) throw std::logic_error("OutputDirectory: bad file name");
  const std::string path = staging_ + "/" + name;
  registrations_.push_back(std::make_unique<TempRegistration>(path));
  names_.push_back(name);
  return path;
}

void OutputDirectory::Write(const std::string& name, const std::function<void(std::ostream&)>& write) {
  const std::string path = Stage(name);
  const std::string shown = dir_ + "/" + name;
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
  if (fd < 0) {
    const int err = errno;
    ThrowOsError(shown, "cannot create the output file", err);
  }
  WriteChecked(fd, path, shown, NothingWritten().c_str(), write);
}

std::vector<std::string> OutputDirectory::Commit() {
  // Files drawn by others (Stage) are synced here; a name never created is skipped.
  std::vector<std::string> present;
  for (const auto& n : names_) {
    const std::string path = staging_ + "/" + n;
    const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd < 0) {
      const int err = errno;
      if (err == ENOENT) continue;
      ThrowOsError(dir_ + "/" + n, "cannot read back the staged file", err, NothingWritten().c_str());
    }
    const int err = ::fsync(fd) == 0 ? 0 : errno;
    ::close(fd);
    if (err != 0) ThrowOsError(dir_ + "/" + n, "writing failed", err, NothingWritten().c_str());
    present.push_back(n);
  }
  if (dir_existed_) {
    // Refuse before moving anything: a directory in the way would stop the commit half-way.
    for (const auto& n : present) {
      struct stat st {};
      if (::lstat((dir_ + "/" + n).c_str(), &st) == 0 && S_ISDIR(st.st_mode)) {
        ThrowOsError(dir_ + "/" + n, fmt::format("cannot replace it with a {}", naming_.file), EISDIR, NothingWritten().c_str());
      }
    }
  }
  const SignalHold hold;
  if (dir_existed_) {
    for (const auto& n : present) {
      if (std::rename((staging_ + "/" + n).c_str(), (dir_ + "/" + n).c_str()) != 0) {
        const int err = errno;  // files moved so far stay: only a DIR changed under us gets here
        ThrowOsError(dir_ + "/" + n, "cannot move the finished file into place", err);
      }
    }
    ::rmdir(staging_.c_str());
    SyncDirectory(dir_);
  } else {
    if (std::rename(staging_.c_str(), dir_.c_str()) != 0) {
      const int err = errno;
      ThrowOsError(dir_, fmt::format("cannot move the finished {} into place", naming_.noun), err, NothingWritten().c_str());
    }
    SyncDirectory(Dirname(dir_));
  }
  committed_ = true;
  registrations_.clear();  // before the signals are let through again
  return present;
}

}  // namespace rlg::sim
