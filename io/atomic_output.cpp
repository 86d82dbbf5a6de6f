#include "io/atomic_output.h"

#include <cerrno>
#include <cstdio>
#include <fcntl.h>
#include <fmt/format.h>
#include <memory>
#include <sys/stat.h>
#include <unistd.h>

#include "io/checked_stream.h"
#include "io/signal_cleanup.h"
#include "sim/errors.h"

namespace rlg::io {
namespace {

/// What a failed output leaves: nothing (a file or a report is whole or absent).
const char* const kNoFile = " (nothing written)";

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

std::string PartialName(const std::string& path) {
  const std::string dir = Dirname(path);
  const std::string name = fmt::format(".{}.rlgtherm-partial-{}", Basename(path), ::getpid());
  return path.find('/') == std::string::npos ? name : (dir == "/" ? "/" : dir + "/") + name;
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

}  // namespace rlg::io
