#include "boicp/mapping/pair_result.hpp"

namespace boicp {

PairResult MakePairResult(const PairIndex& pair, const RegistrationResult& registration,
                          uint64_t seed) {
  const RegistrationResult& r = registration;
  PairResult out;
  out.pair = pair;
  out.transform = r.transform;
  out.objective = r.objective;
  out.fitness = r.fitness;
  out.inlier_rmse = r.inlier_rmse;
  out.confidence = r.confidence;
  out.doubtful = r.doubtful;
  out.overlap = r.overlap;
  out.search_reach = r.search_reach;
  out.answered_by = r.answered_by;
  out.evaluations = r.evaluations;
  out.runtime_s = r.runtime_s;
  out.seed = seed;
  out.information = r.information;
  out.unconstrained = r.unconstrained;
  return out;
}

KeyframePlanner::ProbeOutcome ProbeOutcomeOf(const PairResult& result) {
  return {result.overlap.value_or(result.fitness), result.search_reach.value_or(0.0),
          result.doubtful};
}

PairConstraint ConstraintOf(const PairResult& result) {
  return {result.pair, result.transform, result.information, result.confidence};
}

const std::vector<PairResultField>& PairResultFields() {
  constexpr unsigned kEverywhere = kPairFile | kPairListing | kPairApi;
  static const std::vector<PairResultField> kFields = {
      {"transform", &PairResult::transform, kEverywhere},
      {"objective", &PairResult::objective, kEverywhere},
      {"fitness", &PairResult::fitness, kEverywhere},
      {"inlier_rmse", &PairResult::inlier_rmse, kEverywhere},
      {"confidence", &PairResult::confidence, kEverywhere},
      {"doubtful", &PairResult::doubtful, kEverywhere},
      {"overlap", &PairResult::overlap, kEverywhere},
      {"search_reach", &PairResult::search_reach, kEverywhere},
      {"answered_by", &PairResult::answered_by, kEverywhere},
      {"evaluations", &PairResult::evaluations, kEverywhere},
      {"runtime_s", &PairResult::runtime_s, kEverywhere},
      {"seed", &PairResult::seed, kEverywhere},
      // The daemon keeps the information matrix beside the API's message.
      {"information", &PairResult::information, kPairFile},
      {"unconstrained", &PairResult::unconstrained, kPairFile | kPairListing},
      // A pair file is written as its pair finishes, before the graph is known.
      {"in_graph", &PairResult::in_graph, kPairListing | kPairApi},
      // The plan says why each pair ran, when the pipeline lists it.
      {"kind", &PairResult::kind, kPairListing | kPairApi},
      {"found_by", &PairResult::found_by, kPairListing | kPairApi},
      {"left_out_because", &PairResult::left_out_because, kPairListing | kPairApi},
      {"finished_at", &PairResult::finished_at, kPairApi},
  };
  return kFields;
}

}  // namespace boicp
