#pragma once
/// \file
/// SIGINT/SIGTERM -> one clean stop. Construct `ShutdownSignal` first thing in main(), before any
/// thread exists (DDS, HTTP): it blocks both signals in every thread created afterwards and waits
/// for them on a thread of its own, so no handler runs at an arbitrary point.

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <functional>
#include <mutex>
#include <thread>

namespace telltale {

class ShutdownSignal {
 public:
  ShutdownSignal();
  ~ShutdownSignal();
  ShutdownSignal(const ShutdownSignal&) = delete;
  ShutdownSignal& operator=(const ShutdownSignal&) = delete;

  /// Called once, on the signal thread, when SIGINT or SIGTERM arrives (or request() is called).
  void on_stop(std::function<void()> callback);
  [[nodiscard]] bool stop_requested() const { return stop_.load(); }
  /// Waits up to `timeout`; true when a stop was requested.
  bool wait_for(std::chrono::nanoseconds timeout);
  /// Asks for a stop from inside the program.
  void request();
  /// The signal that stopped us (0 if request() did).
  [[nodiscard]] int signal_number() const { return signo_.load(); }

 private:
  void trigger(int signo);

  std::atomic<bool> stop_{false};
  std::atomic<int> signo_{0};
  std::atomic<bool> exiting_{false};
  std::mutex mutex_;
  std::condition_variable cv_;
  std::function<void()> callback_;
  std::thread thread_;
};

/// Wall-clock UTC now, ns since 1970 (the boat's clock).
[[nodiscard]] unsigned long long utc_now_ns();

}  // namespace telltale
