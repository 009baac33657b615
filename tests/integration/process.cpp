#include "process.hpp"

#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <poll.h>
#include <signal.h>
#include <sys/file.h>
#include <sys/prctl.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <stdexcept>
#include <thread>

namespace telltale::testing {

namespace {
// A test that writes to a socket the shore has closed (it answers a hostile request at once and
// hangs up) gets EPIPE, as a real client does, instead of dying of SIGPIPE.
const bool kSigpipeIgnored = [] { return ::signal(SIGPIPE, SIG_IGN) != SIG_ERR; }();
}  // namespace

Process::Process(std::vector<std::string> argv, std::vector<std::string> env) {
  // Everything the child needs is built before fork: after it, only async-signal-safe calls.
  std::vector<char*> args;
  for (auto& a : argv) args.push_back(a.data());
  args.push_back(nullptr);
  std::vector<char*> envp;
  // An extra entry replaces the inherited one of the same name (getenv finds the first).
  const auto overridden = [&](const char* entry) {
    for (const auto& e : env) {
      const auto eq = e.find('=');
      if (eq != std::string::npos && std::strncmp(entry, e.data(), eq + 1) == 0) return true;
    }
    return false;
  };
  for (char** e = environ; *e; ++e)
    if (!overridden(*e)) envp.push_back(*e);
  for (auto& e : env) envp.push_back(e.data());
  envp.push_back(nullptr);
  int fds[2];
  if (pipe2(fds, O_CLOEXEC) != 0) throw std::runtime_error("pipe failed");
  const pid_t parent = getpid();
  pid_ = fork();
  if (pid_ < 0) throw std::runtime_error("fork failed");
  if (pid_ == 0) {
    // Child: die with the test, even if the test crashes.
    prctl(PR_SET_PDEATHSIG, SIGKILL);
    if (getppid() != parent) _exit(127);
    // Signals the test runner blocked must not stay blocked in the child.
    sigset_t none;
    sigemptyset(&none);
    sigprocmask(SIG_SETMASK, &none, nullptr);
    // An ignored signal stays ignored across execve: the child gets SIGPIPE's default back.
    ::signal(SIGPIPE, SIG_DFL);
    dup2(fds[1], STDOUT_FILENO);
    execve(args[0], args.data(), envp.data());
    _exit(127);
  }
  close(fds[1]);
  stdout_fd_ = fds[0];
}

Process::~Process() {
  if (running()) stop(SIGTERM, std::chrono::seconds(5));
  if (stdout_fd_ >= 0) close(stdout_fd_);
}

bool Process::read_some(std::chrono::milliseconds timeout) {
  pollfd p{stdout_fd_, POLLIN, 0};
  if (poll(&p, 1, static_cast<int>(timeout.count())) <= 0) return false;
  char buf[4096];
  const ssize_t n = read(stdout_fd_, buf, sizeof buf);
  if (n <= 0) return false;
  output_.append(buf, static_cast<std::size_t>(n));
  return true;
}

std::optional<std::string> Process::wait_for_line(const std::string& prefix,
                                                  std::chrono::milliseconds timeout) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  for (;;) {
    std::size_t eol;
    while ((eol = output_.find('\n', scanned_)) != std::string::npos) {
      std::string line = output_.substr(scanned_, eol - scanned_);
      scanned_ = eol + 1;
      if (line.rfind(prefix, 0) == 0) return line;
    }
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(
        deadline - std::chrono::steady_clock::now());
    if (left.count() <= 0) return std::nullopt;
    if (!read_some(std::min(left, std::chrono::milliseconds(100))) && !running())
      return std::nullopt;
  }
}

bool Process::running() {
  if (exited_) return false;
  int status = 0;
  const pid_t r = waitpid(pid_, &status, WNOHANG);
  if (r == pid_) {
    exited_ = true;
    status_ = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
    return false;
  }
  return true;
}

int Process::stop(int signo, std::chrono::milliseconds timeout) {
  if (!running()) return status_;
  kill(pid_, signo);
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  while (std::chrono::steady_clock::now() < deadline) {
    read_some(std::chrono::milliseconds(20));  // keep the pipe drained so the child never blocks
    if (!running()) return status_;
  }
  kill(pid_, SIGKILL);
  waitpid(pid_, nullptr, 0);
  exited_ = true;
  status_ = -1;
  return -1;
}

int free_loopback_port(int socket_type) {
  const int fd = ::socket(AF_INET, socket_type, 0);
  if (fd < 0) return 0;
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  socklen_t len = sizeof a;
  const bool ok = ::bind(fd, reinterpret_cast<sockaddr*>(&a), sizeof a) == 0 &&
                  ::getsockname(fd, reinterpret_cast<sockaddr*>(&a), &len) == 0;
  ::close(fd);
  return ok ? ntohs(a.sin_port) : 0;
}

int unique_domain() {
  // One of 100..229, held with an exclusive lock on a file of its own for the life of this
  // process, so tests run in parallel never share a domain (a process-id spread alone collided:
  // a boat of one test was acknowledged by another test's shore). The search starts at a place
  // given by the process id; the lock goes when the process ends, however it ends.
  static const int domain = [] {
    const int start = static_cast<int>(getpid() % 130);
    for (int i = 0; i < 130; ++i) {
      const int d = 100 + (start + i) % 130;
      const std::string lock = (std::filesystem::temp_directory_path() /
                                ("telltale_test_domain_" + std::to_string(d) + ".lock"))
                                   .string();
      const int fd = ::open(lock.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0666);
      if (fd < 0) continue;
      if (::flock(fd, LOCK_EX | LOCK_NB) == 0) return d;  // fd kept open: the lock is held
      ::close(fd);
    }
    throw std::runtime_error("no free DDS test domain in 100..229");
  }();
  (void)kSigpipeIgnored;
  return domain;
}

std::string make_temp_dir() {
  std::string tmpl = (std::filesystem::temp_directory_path() / "telltale_test_XXXXXX").string();
  if (!mkdtemp(tmpl.data())) throw std::runtime_error("mkdtemp failed");
  return tmpl;
}

// TELLTALE_TEST_BIN_DIR runs the tests against other binaries (an older build, to see a test
// fail before its fix).
std::string bin_dir() {
  const char* other = std::getenv("TELLTALE_TEST_BIN_DIR");
  return other && *other ? other : TELLTALE_BIN_DIR;
}

}  // namespace telltale::testing
