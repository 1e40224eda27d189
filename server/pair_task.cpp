#include "pair_task.hpp"

#include "boicp/mapping/batch_pair.hpp"
#include "rpc_names.hpp"

namespace boicp::server {

PairOutcome RegisterJobPair(const JobSpec& spec, const PairIndex& pair,
                            const std::function<bool()>& stop_requested) {
  // The gRPC-free part is core's, shared with `boicp map`.
  const BatchPairResult batch = RegisterBatchPair(spec.scans, pair, spec.config, stop_requested);
  const RegistrationResult& r = batch.registration;
  PairOutcome outcome;
  outcome.information = batch.information;
  ::boicp::v1::PairResult& out = outcome.result;
  out.set_source(static_cast<uint32_t>(pair.source));
  out.set_target(static_cast<uint32_t>(pair.target));
  out.set_source_scan_id(spec.scan_ids.at(static_cast<size_t>(pair.source)));
  out.set_target_scan_id(spec.scan_ids.at(static_cast<size_t>(pair.target)));
  TransformToProto(r.transform, out.mutable_transform());
  out.set_objective(r.objective);
  out.set_fitness(r.fitness);
  out.set_inlier_rmse(r.inlier_rmse);
  out.set_confidence(r.confidence);
  out.set_doubtful(r.doubtful);
  out.set_overlap(r.overlap);
  out.set_evaluations(static_cast<uint32_t>(r.evaluations));
  out.set_runtime_s(r.runtime_s);
  out.set_finished_at(NowSeconds());
  out.set_seed(batch.seed);
  out.set_in_graph(true);
  return outcome;
}

}  // namespace boicp::server
