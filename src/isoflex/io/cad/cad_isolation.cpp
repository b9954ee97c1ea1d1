#include "isoflex/io/cad/cad_isolation.hpp"

#include <fcntl.h>
#include <fmt/format.h>
#include <poll.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <climits>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <optional>
#include <vector>

#include "isoflex/io/cad/cad_error.hpp"
#include "isoflex/io/cad/cad_wire.hpp"

namespace isoflex::io::detail {

namespace {

// Messages from the child: one kind byte, the payload's length (8 bytes), the payload.
enum Kind : char {
  stage_message = 'S',  // what the reader starts next (text)
  model_message = 'M',  // the result (cad_wire.hpp)
  error_message = 'E'   // the reader's error: code, file, message (strings_to_bytes)
};
constexpr std::size_t kHeader = 1 + sizeof(std::uint64_t);

// --- The child ---------------------------------------------------------------------------------

void write_all(int fd, const char* p, std::size_t n) {
  while (n > 0) {
    const ssize_t k = ::write(fd, p, n);
    if (k < 0 && errno == EINTR) continue;
    if (k <= 0) return;  // the parent is gone; nothing to tell
    p += k;
    n -= static_cast<std::size_t>(k);
  }
}

void send(int fd, Kind kind, const std::string& payload) {
  std::string frame(kHeader, '\0');
  frame[0] = kind;
  const std::uint64_t n = payload.size();
  std::memcpy(frame.data() + 1, &n, sizeof n);
  frame += payload;
  write_all(fd, frame.data(), frame.size());
}

void send_stage(void* fd, const char* stage) {
  send(*static_cast<int*>(fd), stage_message, stage);
}

[[noreturn]] void run_child(int fd, const std::filesystem::path& file, CadReadFn read) {
  // A crash must not leave a core file, and nothing may be printed: results go through the pipe.
  const rlimit no_core{0, 0};
  ::setrlimit(RLIMIT_CORE, &no_core);
  if (const int null = ::open("/dev/null", O_WRONLY); null >= 0) {
    ::dup2(null, STDOUT_FILENO);
    ::dup2(null, STDERR_FILENO);
  }
  int status = 0;
  try {
    CadModel model;
    std::string where, message;
    int channel = fd;
    const int code = read(file.c_str(), send_stage, &channel, &model, &where, &message);
    if (code == 0)
      send(fd, model_message, to_bytes(model));
    else
      send(fd, error_message, strings_to_bytes({std::to_string(code), where, message}));
  } catch (...) {
    status = 1;  // out of memory while sending: the parent reports an exit without a result
  }
  // _exit: no exit handlers, no flushing of stdio or stream buffers copied from the parent.
  ::_exit(status);
}

// --- The parent --------------------------------------------------------------------------------

struct ChildReport {
  std::string stage = "starting the reader";
  std::optional<CadModel> model;
  std::optional<std::vector<std::string>> error;
};

// Takes every complete message off the front of `buffer`.
void take_messages(std::string& buffer, ChildReport& report) {
  std::size_t at = 0;
  while (buffer.size() - at >= kHeader) {
    std::uint64_t n = 0;
    std::memcpy(&n, buffer.data() + at + 1, sizeof n);
    if (buffer.size() - at - kHeader < n) break;
    const std::string_view payload(buffer.data() + at + kHeader, n);
    switch (buffer[at]) {
      case stage_message:
        report.stage = std::string(payload);
        break;
      case model_message:
        report.model = model_from_bytes(payload);
        break;
      case error_message:
        report.error = strings_from_bytes(payload);
        break;
      default:
        throw std::runtime_error("unknown message from the CAD reader process");
    }
    at += kHeader + n;
  }
  buffer.erase(0, at);
}

int wait_for(pid_t pid) {
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  return status;
}

std::string signal_text(int sig) {
  const char* abbrev = ::sigabbrev_np(sig);
  const char* what = ::strsignal(sig);
  return fmt::format("SIG{}: {}", abbrev ? abbrev : std::to_string(sig).c_str(),
                     what ? what : "unknown signal");
}

// Closes the pipe and kills and reaps the child on every way out of the parent.
struct ChildGuard {
  pid_t pid;
  int fd;
  bool reaped = false;
  ~ChildGuard() {
    ::close(fd);
    if (!reaped) {
      ::kill(pid, SIGKILL);
      wait_for(pid);
    }
  }
};

}  // namespace

CadModel read_in_child(const std::filesystem::path& file, CadReadFn read, double time_limit_s) {
  const std::string name = file.string();
  int fds[2];
  if (::pipe2(fds, O_CLOEXEC) != 0)
    throw CadError(
        name, fmt::format("cannot start the CAD reader process (pipe: {})", std::strerror(errno)));
  const pid_t pid = ::fork();
  if (pid < 0) {
    const int e = errno;
    ::close(fds[0]);
    ::close(fds[1]);
    throw CadError(name,
                   fmt::format("cannot start the CAD reader process (fork: {})", std::strerror(e)));
  }
  if (pid == 0) {
    ::close(fds[0]);
    run_child(fds[1], file, read);
  }
  ::close(fds[1]);
  ChildGuard child{pid, fds[0]};

  using Clock = std::chrono::steady_clock;
  const auto deadline =
      Clock::now() + std::chrono::duration_cast<Clock::duration>(
                         std::chrono::duration<double>(std::min(time_limit_s, 1e9)));
  ChildReport report;
  std::string buffer;
  std::vector<char> chunk(1 << 16);
  for (;;) {
    const auto left = std::chrono::ceil<std::chrono::milliseconds>(deadline - Clock::now());
    if (left.count() <= 0)
      throw CadError(name, fmt::format("OpenCASCADE did not finish within {:g} s while {} (the "
                                       "reading process was stopped; the time limit is "
                                       "ISOFLEX_CAD_TIME_LIMIT seconds, default 60)",
                                       time_limit_s, report.stage));
    pollfd p{fds[0], POLLIN, 0};
    const int ready =
        ::poll(&p, 1, static_cast<int>(std::min<std::int64_t>(left.count(), INT_MAX)));
    if (ready < 0 && errno != EINTR)
      throw CadError(name,
                     fmt::format("lost the CAD reader process (poll: {})", std::strerror(errno)));
    if (ready <= 0) continue;
    const ssize_t n = ::read(fds[0], chunk.data(), chunk.size());
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) break;  // end of file: the child has exited (or closed the pipe in dying)
    buffer.append(chunk.data(), static_cast<std::size_t>(n));
    try {
      take_messages(buffer, report);
    } catch (const std::exception& e) {
      throw CadError(name,
                     fmt::format("garbled result from the CAD reader process ({})", e.what()));
    }
  }
  const int status = wait_for(pid);
  child.reaped = true;

  if (report.model && WIFEXITED(status) && WEXITSTATUS(status) == 0) {
    report.model->file = file;
    return std::move(*report.model);
  }
  if (report.error && report.error->size() == 3) {
    const auto& e = *report.error;
    if (e[0] == "1") throw CadError(e[1], e[2]);
    throw CadError(name, fmt::format("{} while {}", e[2], report.stage));
  }
  if (WIFSIGNALED(status))
    throw CadError(name, fmt::format("OpenCASCADE crashed ({}) while {} (the file is probably "
                                     "malformed; the crash was contained in a child process)",
                                     signal_text(WTERMSIG(status)), report.stage));
  throw CadError(name, fmt::format("the CAD reader process ended without a result (exit status "
                                   "{}) while {}",
                                   WIFEXITED(status) ? WEXITSTATUS(status) : -1, report.stage));
}

}  // namespace isoflex::io::detail
