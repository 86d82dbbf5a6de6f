#include "validation/plugin.h"

#include <cerrno>
#include <cmath>
#include <csignal>
#include <cstdlib>
#include <cstring>
#include <fcntl.h>
#include <fmt/format.h>
#include <poll.h>
#include <sstream>
#include <sys/wait.h>
#include <unistd.h>

#include "io/csv.h"
#include "sim/errors.h"

namespace rlg::validation {
namespace {

struct ProcessResult {
  int wait_status = 0;
  std::string out, err;
};

/// Closes a descriptor once.
struct Fd {
  int fd = -1;
  ~Fd() { Close(); }
  void Close() {
    if (fd >= 0) ::close(fd);
    fd = -1;
  }
};

/// Ignores SIGPIPE while it lives: a plug-in that exits without reading its input must give an
/// error message, not kill rlgtherm.
class IgnoreSigpipe {
 public:
  IgnoreSigpipe() {
    struct sigaction ignore {};
    ignore.sa_handler = SIG_IGN;
    sigemptyset(&ignore.sa_mask);
    ::sigaction(SIGPIPE, &ignore, &old_);
  }
  ~IgnoreSigpipe() { ::sigaction(SIGPIPE, &old_, nullptr); }
  IgnoreSigpipe(const IgnoreSigpipe&) = delete;
  IgnoreSigpipe& operator=(const IgnoreSigpipe&) = delete;

 private:
  struct sigaction old_ {};
};

/// `/bin/sh -c command` in `dir` with `input` on its stdin; stdout and stderr collected. Writes
/// and reads interleave (poll), so neither side waits on a full pipe.
ProcessResult RunShell(const std::string& command, const std::string& dir, const std::string& input,
                       const std::string& who) {
  // Close-on-exec: a plug-in started on another thread meanwhile (a population runs gyros on
  // every core) must not inherit these pipes, or this plug-in waits for end-of-input, and
  // rlgtherm for its output's end, until that other one exits.
  int in[2], out[2], err[2];
  if (::pipe2(in, O_CLOEXEC) != 0) throw std::runtime_error(fmt::format("{}: pipe: {}", who, std::strerror(errno)));
  Fd in_r{in[0]}, in_w{in[1]};
  if (::pipe2(out, O_CLOEXEC) != 0) throw std::runtime_error(fmt::format("{}: pipe: {}", who, std::strerror(errno)));
  Fd out_r{out[0]}, out_w{out[1]};
  if (::pipe2(err, O_CLOEXEC) != 0) throw std::runtime_error(fmt::format("{}: pipe: {}", who, std::strerror(errno)));
  Fd err_r{err[0]}, err_w{err[1]};
  IgnoreSigpipe ignore_sigpipe;
  const pid_t pid = ::fork();
  if (pid < 0) throw std::runtime_error(fmt::format("{}: fork: {}", who, std::strerror(errno)));
  if (pid == 0) {  // the child: only async-signal-safe calls until exec
    ::signal(SIGPIPE, SIG_DFL);
    ::dup2(in[0], 0);  // dup2 clears close-on-exec on 0, 1 and 2
    ::dup2(out[1], 1);
    ::dup2(err[1], 2);
    // Nothing else of this process: descriptors the host opened without close-on-exec (a
    // Python program's files and pipes) are none of the plug-in's business either.
    ::close_range(3, ~0U, 0);
    if (::chdir(dir.c_str()) != 0) {
      const char msg[] = "cannot enter the suite's directory\n";
      [[maybe_unused]] const auto n = ::write(2, msg, sizeof msg - 1);
      ::_exit(127);
    }
    ::execl("/bin/sh", "sh", "-c", command.c_str(), static_cast<char*>(nullptr));
    ::_exit(127);
  }
  in_r.Close();
  out_w.Close();
  err_w.Close();
  ::fcntl(in_w.fd, F_SETFL, ::fcntl(in_w.fd, F_GETFL) | O_NONBLOCK);
  if (input.empty()) in_w.Close();
  ProcessResult r;
  size_t written = 0;
  char buf[65536];
  while (in_w.fd >= 0 || out_r.fd >= 0 || err_r.fd >= 0) {
    pollfd fds[3] = {{in_w.fd, POLLOUT, 0}, {out_r.fd, POLLIN, 0}, {err_r.fd, POLLIN, 0}};
    if (::poll(fds, 3, -1) < 0) {
      if (errno == EINTR) continue;
      throw std::runtime_error(fmt::format("{}: poll: {}", who, std::strerror(errno)));
    }
    if (in_w.fd >= 0 && fds[0].revents) {
      const ssize_t n = ::write(in_w.fd, input.data() + written, input.size() - written);
      if (n > 0) written += static_cast<size_t>(n);
      // EPIPE: the plug-in stopped reading (it may still write a result, or fail).
      if ((n < 0 && errno != EAGAIN && errno != EINTR) || written == input.size()) in_w.Close();
    }
    for (int k = 1; k < 3; ++k) {
      Fd& fd = k == 1 ? out_r : err_r;
      if (fd.fd < 0 || !fds[k].revents) continue;
      const ssize_t n = ::read(fd.fd, buf, sizeof buf);
      if (n > 0) {
        (k == 1 ? r.out : r.err).append(buf, static_cast<size_t>(n));
      } else if (n == 0 || (errno != EAGAIN && errno != EINTR)) {
        fd.Close();
      }
    }
  }
  while (::waitpid(pid, &r.wait_status, 0) < 0) {
    if (errno != EINTR) throw std::runtime_error(fmt::format("{}: waitpid: {}", who, std::strerror(errno)));
  }
  return r;
}

std::string Trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t\r\n");
  if (b == std::string::npos) return "";
  return s.substr(b, s.find_last_not_of(" \t\r\n") - b + 1);
}

/// The whole of `text` as a finite number, or NaN.
double Number(const std::string& text) {
  if (text.empty()) return NAN;
  char* end = nullptr;
  const double v = std::strtod(text.c_str(), &end);
  return *end == '\0' && std::isfinite(v) ? v : NAN;
}

std::vector<std::string> Split(const std::string& line) {
  std::vector<std::string> fields;
  std::stringstream ss(line);
  for (std::string f; std::getline(ss, f, ',');) fields.push_back(Trim(f));
  if (!line.empty() && line.back() == ',') fields.emplace_back();
  return fields;
}

/// The last lines of a plug-in's stderr, for a message.
std::string Tail(const std::string& err) {
  std::string t = Trim(err);
  size_t at = t.size();
  for (int lines = 0; lines < 5 && at != std::string::npos && at > 0; ++lines) at = t.rfind('\n', at - 1);
  if (at != std::string::npos && at < t.size()) t = t.substr(at + 1);
  if (t.size() > 800) t = "..." + t.substr(t.size() - 800);
  return t.empty() ? "" : "; its stderr ends: " + t;
}

}  // namespace

std::vector<double> ParsePluginOutput(const std::string& text, size_t rows, const std::string& column,
                                      const std::string& who) {
  std::vector<double> values;
  std::istringstream in(text);
  int line_no = 0, index = -1;  // index: the column's field in CSV output; -1 = one number per line
  size_t fields = 0;
  bool first = true;
  for (std::string raw; std::getline(in, raw);) {
    ++line_no;
    const std::string line = Trim(raw);
    if (line.empty() || line[0] == '#') continue;
    if (first) {
      first = false;
      if (std::isnan(Number(line))) {  // a header
        const auto names = Split(line);
        for (size_t i = 0; i < names.size(); ++i)
          if (names[i] == column) index = static_cast<int>(i);
        if (index < 0) {
          throw InputError(fmt::format("{}: output line {}: expected a number or a CSV header naming column '{}', "
                                       "found '{}'",
                                       who, line_no, column, line.substr(0, 200)));
        }
        fields = names.size();
        continue;
      }
    }
    std::string field = line;
    if (index >= 0) {
      const auto f = Split(line);
      if (f.size() != fields) {
        throw InputError(fmt::format("{}: output line {}: {} fields, the header has {}", who, line_no, f.size(), fields));
      }
      field = f[static_cast<size_t>(index)];
    }
    const double v = Number(field);
    if (std::isnan(v)) {
      throw InputError(fmt::format("{}: output line {}: expected a finite number{}, found '{}'", who, line_no,
                                   index >= 0 ? fmt::format(" in column '{}'", column) : "", field.substr(0, 200)));
    }
    values.push_back(v);
  }
  if (values.size() != rows) {
    throw InputError(fmt::format("{}: wrote {} values for the {} rows it was given (one per row expected)", who,
                                 values.size(), rows));
  }
  return values;
}

std::vector<double> RunPlugin(const PluginCompensator& plugin, const sim::Run& run) {
  const std::string who = fmt::format("compensator '{}' (`{}`) on {}", plugin.name, plugin.command, run.Where());
  sim::Trace one;
  one.runs.push_back(run);
  const ProcessResult r = RunShell(plugin.command, plugin.directory, io::FormatTraceCsv(one), who);
  if (WIFSIGNALED(r.wait_status)) {
    throw InputError(fmt::format("{}: killed by signal {}{}", who, WTERMSIG(r.wait_status), Tail(r.err)));
  }
  if (WEXITSTATUS(r.wait_status) != 0) {
    throw InputError(fmt::format("{}: exited with status {}{}", who, WEXITSTATUS(r.wait_status), Tail(r.err)));
  }
  return ParsePluginOutput(r.out, run.size(), plugin.column, who);
}

}  // namespace rlg::validation
