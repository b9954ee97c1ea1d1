#pragma once
// The `isoflex` executable of the build (ISOFLEX_BINARY) as a child process that a test can
// signal while it runs, and waiting for it with a deadline.
#include <fcntl.h>
#include <signal.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <functional>
#include <string>
#include <thread>
#include <vector>

namespace isoflex::test {

// How a child process ended.
struct ChildEnd {
  bool exited = false;  // it called exit (else: killed by `signal`, or still running)
  int code = -1;        // exit code when exited
  int signal = 0;       // the signal that killed it
};

// `isoflex ARGS` with stdout and stderr appended to `log`, started by the constructor; killed
// (SIGKILL) and reaped by the destructor if it is still running.
class IsoflexChild {
 public:
  IsoflexChild(const std::vector<std::string>& args, const std::filesystem::path& log)
      : args_(args), log_(log.string()) {
    args_.insert(args_.begin(), ISOFLEX_BINARY);
    std::vector<char*> argv;
    for (auto& a : args_) argv.push_back(a.data());
    argv.push_back(nullptr);
    pid_ = ::fork();
    if (pid_ != 0) return;
    // The child: async-signal-safe calls only until exec.
    const int fd = ::open(log_.c_str(), O_WRONLY | O_CREAT | O_APPEND, 0644);
    if (fd >= 0) {
      ::dup2(fd, 1);
      ::dup2(fd, 2);
    }
    // A test runner started in the background may pass SIGINT on as ignored, and isoflex keeps
    // an ignored signal ignored: the child gets the default dispositions back.
    ::signal(SIGINT, SIG_DFL);
    ::signal(SIGTERM, SIG_DFL);
    ::execv(argv[0], argv.data());
    ::_exit(127);
  }
  ~IsoflexChild() {
    if (pid_ > 0 && !done_) {
      ::kill(pid_, SIGKILL);
      ::waitpid(pid_, nullptr, 0);
    }
  }
  IsoflexChild(const IsoflexChild&) = delete;
  IsoflexChild& operator=(const IsoflexChild&) = delete;

  bool started() const { return pid_ > 0; }
  void send(int sig) const { ::kill(pid_, sig); }

  // Waits up to `timeout` for the child to end; ChildEnd{} (neither exited nor signalled) if it
  // is still running then.
  ChildEnd wait(std::chrono::milliseconds timeout) {
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    while (!done_) {
      int status = 0;
      const pid_t r = ::waitpid(pid_, &status, WNOHANG);
      if (r == pid_) {
        done_ = true;
        if (WIFEXITED(status)) end_ = {true, WEXITSTATUS(status), 0};
        if (WIFSIGNALED(status)) end_ = {false, -1, WTERMSIG(status)};
        break;
      }
      if (r < 0 || std::chrono::steady_clock::now() > deadline) break;
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    return end_;
  }

 private:
  std::vector<std::string> args_;  // the binary, then ARGS
  std::string log_;
  pid_t pid_ = -1;
  bool done_ = false;
  ChildEnd end_;
};

// Polls `condition` every 10 ms until it holds or `timeout` has passed; returns whether it held.
inline bool poll_until(const std::function<bool()>& condition, std::chrono::milliseconds timeout) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  while (!condition()) {
    if (std::chrono::steady_clock::now() > deadline) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  return true;
}

}  // namespace isoflex::test
