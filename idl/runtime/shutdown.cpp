#include "shutdown.hpp"

#include <pthread.h>
#include <signal.h>

namespace telltale {
namespace {
sigset_t stop_signals() {
  sigset_t set;
  sigemptyset(&set);
  sigaddset(&set, SIGINT);
  sigaddset(&set, SIGTERM);
  return set;
}
}  // namespace

ShutdownSignal::ShutdownSignal() {
  const sigset_t set = stop_signals();
  pthread_sigmask(SIG_BLOCK, &set, nullptr);
  thread_ = std::thread([this] {
    const sigset_t wait_set = stop_signals();
    int signo = 0;
    while (sigwait(&wait_set, &signo) == 0) {
      if (exiting_.load()) return;  // the destructor's wake-up
      trigger(signo);
    }
  });
}

ShutdownSignal::~ShutdownSignal() {
  exiting_.store(true);
  pthread_kill(thread_.native_handle(), SIGTERM);
  thread_.join();
}

void ShutdownSignal::on_stop(std::function<void()> callback) {
  std::lock_guard lock(mutex_);
  callback_ = std::move(callback);
}

bool ShutdownSignal::wait_for(std::chrono::nanoseconds timeout) {
  std::unique_lock lock(mutex_);
  return cv_.wait_for(lock, timeout, [this] { return stop_.load(); });
}

void ShutdownSignal::request() { trigger(0); }

void ShutdownSignal::trigger(int signo) {
  std::function<void()> cb;
  {
    std::lock_guard lock(mutex_);
    if (stop_.exchange(true)) return;
    signo_.store(signo);
    cb = callback_;
  }
  cv_.notify_all();
  if (cb) cb();
}

unsigned long long utc_now_ns() {
  return static_cast<unsigned long long>(
      std::chrono::duration_cast<std::chrono::nanoseconds>(
          std::chrono::system_clock::now().time_since_epoch())
          .count());
}

}  // namespace telltale
