#pragma once
// A pair registration of a job as the API reports and stores it.

#include "boicp/mapping/batch_pair.hpp"
#include "boicp/mapping/pair_store.hpp"
#include "boicp/v1/map_builder.pb.h"
#include "job_spec.hpp"

namespace boicp::server {

/// Core's BatchPairResult of `pair` as the API's PairResult, stamped with
/// the finishing time and marked in the graph (until assembly says otherwise).
::boicp::v1::PairResult PairResultToProto(const JobSpec& spec, const PairIndex& pair,
                                          const BatchPairResult& batch);

/// A stored result as the pipeline needs it. Results stored before overlap
/// was computed plan with their fitness; before confidence was calibrated
/// (no doubtful mark) they are fully trusted, as they were then.
FinishedPair FinishedFromProto(const ::boicp::v1::PairResult& result,
                               const InformationMatrix& information);

}  // namespace boicp::server
