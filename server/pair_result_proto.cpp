#include "pair_result_proto.hpp"

#include "boicp/rpc/proto_convert.hpp"

namespace boicp::server {

::boicp::v1::PairResult PairResultToProto(const JobSpec& spec, const PairIndex& pair,
                                          const BatchPairResult& batch) {
  const RegistrationResult& r = batch.registration;
  ::boicp::v1::PairResult out;
  out.set_source(static_cast<uint32_t>(pair.source));
  out.set_target(static_cast<uint32_t>(pair.target));
  out.set_source_scan_id(spec.scan_ids.at(static_cast<size_t>(pair.source)));
  out.set_target_scan_id(spec.scan_ids.at(static_cast<size_t>(pair.target)));
  rpc::TransformToProto(r.transform, out.mutable_transform());
  out.set_objective(r.objective);
  out.set_fitness(r.fitness);
  out.set_inlier_rmse(r.inlier_rmse);
  out.set_confidence(r.confidence);
  out.set_doubtful(r.doubtful);
  out.set_overlap(r.overlap);
  out.set_search_reach(r.search_reach);
  out.set_evaluations(static_cast<uint32_t>(r.evaluations));
  out.set_answered_by(RungName(r.answered_by));
  out.set_runtime_s(r.runtime_s);
  out.set_finished_at(rpc::NowSeconds());
  out.set_seed(batch.seed);
  out.set_in_graph(true);
  return out;
}

FinishedPair FinishedFromProto(const ::boicp::v1::PairResult& result,
                               const InformationMatrix& information) {
  FinishedPair finished;
  finished.pair = {static_cast<int>(result.source()), static_cast<int>(result.target())};
  finished.transform = rpc::TransformFromProto(result.transform(), "stored pair");
  finished.information = information;
  finished.confidence = result.has_doubtful() ? result.confidence() : 1.0;
  finished.planner_overlap = result.has_overlap() ? result.overlap() : result.fitness();
  finished.doubtful = result.doubtful();
  finished.search_reach = result.search_reach();
  return finished;
}

}  // namespace boicp::server
