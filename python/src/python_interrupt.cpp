#include "python_interrupt.hpp"

namespace boicp::python {
namespace py = pybind11;

namespace {
constexpr std::chrono::milliseconds kPollInterval{50};
}  // namespace

bool PythonInterrupt::Requested() {
  if (stop_) return true;
  {
    std::lock_guard<std::mutex> lock(poll_mutex_);
    const auto now = std::chrono::steady_clock::now();
    if (now - last_poll_ < kPollInterval) return false;
    last_poll_ = now;
  }
  py::gil_scoped_acquire gil;
  // Handlers run on Python's main thread only; elsewhere this returns 0.
  if (PyErr_CheckSignals() != 0) Keep(py::error_already_set());
  return stop_;
}

void PythonInterrupt::Record(py::error_already_set& error) { Keep(std::move(error)); }

void PythonInterrupt::Keep(py::error_already_set&& error) {
  std::lock_guard<std::mutex> lock(error_mutex_);
  if (!error_) error_ = std::make_unique<py::error_already_set>(std::move(error));
  stop_ = true;
}

void PythonInterrupt::RaiseIfRecorded() {
  std::unique_ptr<py::error_already_set> error;
  {
    std::lock_guard<std::mutex> lock(error_mutex_);
    error = std::move(error_);
  }
  if (error) throw std::move(*error);
}

}  // namespace boicp::python
