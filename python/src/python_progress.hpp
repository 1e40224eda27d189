#pragma once
// The map pipeline's progress as calls of a Python function, one dict per
// event, and the pipeline's stop requests from Ctrl-C or that function's
// exceptions (PythonInterrupt). Every report comes from the thread that runs
// the pipeline, which holds no GIL: each call takes it.

#include <pybind11/pybind11.h>

#include "boicp/mapping/map_progress.hpp"
#include "python_interrupt.hpp"

namespace boicp::python {

/// Events passed to `callback` (None: none), each a dict with "event":
/// - "pair": a pair finished; "source", "target" (scan indices), "reused",
///   "confidence", "doubtful", "answered_by", and the counts "done",
///   "total", "doubtful_total";
/// - "stage": a stage began; "stage" (MapStageName), "total";
/// - "fusing": a scan fused or an output written; "stage", "done", "total".
class PythonMapProgress : public MapProgressSink {
 public:
  PythonMapProgress(pybind11::object callback, PythonInterrupt& interrupt)
      : callback_(std::move(callback)), interrupt_(interrupt) {}

  void PairFinished(const PairResult& pair, bool reused, const PairCounts& counts) override;
  void Heartbeat() override { interrupt_.Requested(); }
  void StageStarted(MapStage stage, int total) override;
  void AssemblyStep(const AssemblyProgress& progress) override;

 private:
  // Calls the callback (under the GIL) with the dict `fill` makes; an
  // exception it raises is recorded and stops the run.
  template <typename Fill>
  void Emit(Fill fill);

  pybind11::object callback_;
  PythonInterrupt& interrupt_;
};

}  // namespace boicp::python
