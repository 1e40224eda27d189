#include "pair_task.hpp"

#include "boicp/bo_icp.hpp"
#include "boicp/voxel_cloud.hpp"
#include "proto_convert.hpp"

namespace boicp::server {
namespace {

Points Downsample(const Points& points, double voxel) {
  VoxelAccumulator grid(voxel);
  grid.Add(points);
  return grid.Centroids();
}

}  // namespace

PairOutcome RegisterJobPair(const JobSpec& spec, const PairIndex& pair,
                            const std::function<bool()>& stop_requested) {
  const ScanSource& source = spec.scans.at(static_cast<size_t>(pair.source));
  const ScanSource& target = spec.scans.at(static_cast<size_t>(pair.target));
  const Points source_points = LoadPointCloud(source.path, source.load).points;
  const Points target_points = LoadPointCloud(target.path, target.load).points;

  BoIcpConfig config = spec.config;
  config.seed = PairSeed(spec.config.seed, pair);
  RegistrationCallbacks callbacks;
  callbacks.stop_requested = stop_requested;
  const RegistrationResult r =
      RegisterPair(source_points, target_points, config, PairPrior(source, target), callbacks);

  PairOutcome outcome;
  const double voxel = config.EffectiveRefineVoxel();
  outcome.information =
      PairInformation(Downsample(source_points, voxel), Downsample(target_points, voxel),
                      r.transform, config.EffectiveInlierDistance());
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
  out.set_evaluations(static_cast<uint32_t>(r.evaluations));
  out.set_runtime_s(r.runtime_s);
  out.set_finished_at(NowSeconds());
  out.set_seed(config.seed);
  out.set_in_graph(true);
  return outcome;
}

}  // namespace boicp::server
