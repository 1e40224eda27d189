#pragma once
// Ctrl-C, and exceptions from Python callbacks, while the engine runs with
// the GIL released: Python runs its signal handlers only when asked, so the
// engine's stop polls ask, and a KeyboardInterrupt (or a callback's
// exception) stops the run and is raised once it has stopped.

#include <atomic>
#include <chrono>
#include <memory>
#include <mutex>

#include <pybind11/pybind11.h>

namespace boicp::python {

class PythonInterrupt {
 public:
  /// Whether the run should stop: a Python exception was recorded, or a
  /// signal handler raises one now (asked at most every 50 ms, under the
  /// GIL). Thread-safe; call without the GIL.
  bool Requested();

  /// Keeps the Python exception being handled (the first one only) and
  /// stops the run. Call with the GIL held, inside a catch of it.
  void Record(pybind11::error_already_set& error);

  /// Raises the recorded exception, if any. Call with the GIL held.
  void RaiseIfRecorded();

 private:
  // Call with the GIL held.
  void Keep(pybind11::error_already_set&& error);

  std::atomic<bool> stop_{false};
  // Never held while the GIL is acquired: GIL first, then error_mutex_.
  std::mutex poll_mutex_;
  std::chrono::steady_clock::time_point last_poll_{};  // guarded by poll_mutex_
  std::mutex error_mutex_;
  std::unique_ptr<pybind11::error_already_set> error_;  // guarded by error_mutex_
};

}  // namespace boicp::python
