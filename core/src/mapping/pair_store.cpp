#include "boicp/mapping/pair_store.hpp"

namespace boicp {

FinishedPair FinishedFromResult(const PairIndex& pair, const BatchPairResult& result) {
  const RegistrationResult& r = result.registration;
  FinishedPair finished;
  finished.pair = pair;
  finished.transform = r.transform;
  finished.information = result.information;
  finished.confidence = r.confidence;
  finished.planner_overlap = r.overlap;
  finished.doubtful = r.doubtful;
  return finished;
}

PairConstraint ConstraintOf(const FinishedPair& finished) {
  return {finished.pair, finished.transform, finished.information, finished.confidence};
}

}  // namespace boicp
