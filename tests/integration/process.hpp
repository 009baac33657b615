#pragma once
/// \file
/// A child process for integration tests: started with its stdout on a pipe, killed with the
/// test (PR_SET_PDEATHSIG) even when the test crashes, and stopped on scope exit.

#include <sys/types.h>

#include <chrono>
#include <optional>
#include <string>
#include <vector>

namespace telltale::testing {

class Process {
 public:
  /// Starts `argv[0]` with the given arguments and extra environment entries ("NAME=value").
  explicit Process(std::vector<std::string> argv, std::vector<std::string> env = {});
  ~Process();
  Process(const Process&) = delete;
  Process& operator=(const Process&) = delete;

  /// Waits until a stdout line starts with `prefix`; returns that line. Empty on timeout/exit.
  std::optional<std::string> wait_for_line(const std::string& prefix,
                                           std::chrono::milliseconds timeout);
  /// Sends `signo` and waits for exit; returns the exit status (128+signal if killed), or -1 if
  /// the process did not exit within `timeout` (then it is SIGKILLed).
  int stop(int signo, std::chrono::milliseconds timeout = std::chrono::seconds(10));
  [[nodiscard]] bool running();
  [[nodiscard]] pid_t pid() const { return pid_; }
  /// Everything read from stdout so far (for failure messages).
  [[nodiscard]] const std::string& output() const { return output_; }

 private:
  bool read_some(std::chrono::milliseconds timeout);
  pid_t pid_ = -1;
  int stdout_fd_ = -1;
  int status_ = -1;
  bool exited_ = false;
  std::string output_;
  std::size_t scanned_ = 0;
};

/// A DDS domain id for this test process (0..232), unique among concurrently running tests.
int unique_domain();
/// A loopback port free at the time of the call (the OS picks it; bound and released), for a
/// child that must be told its port: SOCK_DGRAM or SOCK_STREAM.
int free_loopback_port(int socket_type);
/// A fresh temporary directory, removed by the caller.
std::string make_temp_dir();
/// Directory of the project's binaries (build/bin).
std::string bin_dir();

}  // namespace telltale::testing
