#include "python_progress.hpp"

#include "boicp/registration/bo_icp.hpp"

namespace boicp::python {
namespace py = pybind11;

template <typename Fill>
void PythonMapProgress::Emit(Fill fill) {
  if (interrupt_.Requested()) return;
  py::gil_scoped_acquire gil;
  if (callback_.is_none()) return;
  try {
    py::dict event;
    fill(event);
    callback_(event);
  } catch (py::error_already_set& e) {
    interrupt_.Record(e);
  }
}

void PythonMapProgress::PairFinished(const PairResult& pair, bool reused,
                                     const PairCounts& counts) {
  Emit([&](py::dict& event) {
    event["event"] = "pair";
    event["source"] = pair.pair.source;
    event["target"] = pair.pair.target;
    event["reused"] = reused;
    event["confidence"] = pair.confidence;
    event["doubtful"] = pair.doubtful;
    event["answered_by"] = RungName(pair.answered_by);
    event["done"] = counts.done;
    event["total"] = counts.total;
    event["doubtful_total"] = counts.doubtful;
  });
}

void PythonMapProgress::StageStarted(MapStage stage, int total) {
  Emit([&](py::dict& event) {
    event["event"] = "stage";
    event["stage"] = MapStageName(stage);
    event["total"] = total;
  });
}

void PythonMapProgress::AssemblyStep(const AssemblyProgress& progress) {
  Emit([&](py::dict& event) {
    event["event"] = "fusing";
    event["stage"] = MapStageName(progress.stage);
    event["done"] = progress.done;
    event["total"] = progress.total;
  });
}

}  // namespace boicp::python
