#include "boicp/mapping/pair_store.hpp"

namespace boicp {

FinishedPair FinishedFromResult(const PairIndex& pair, const BatchPairResult& result) {
  const RegistrationResult& r = result.registration;
  FinishedPair finished;
  finished.pair = pair;
  finished.transform = r.transform;
  finished.information = r.information;
  finished.confidence = r.confidence;
  finished.planner_overlap = r.overlap;
  finished.search_reach = r.search_reach;
  finished.doubtful = r.doubtful;
  return finished;
}

KeyframePlanner::ProbeOutcome ProbeOutcomeOf(const FinishedPair& finished) {
  return {finished.planner_overlap, finished.search_reach, finished.doubtful};
}

PairConstraint ConstraintOf(const FinishedPair& finished) {
  return {finished.pair, finished.transform, finished.information, finished.confidence};
}

}  // namespace boicp
