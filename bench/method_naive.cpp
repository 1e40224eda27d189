// naive: the straightforward port of BO-ICP (config C on the dataset): core's
// RegisterPair with the same stages, seeds, subsample, search boxes, objective
// and refinement as bo-C, except for the speed work: every search evaluation
// calls Open3D's RegistrationICP afresh (which converts the clouds, rebuilds
// the target kd-tree and runs to convergence, never abandoning a start) on
// the whole downsampled source, as the paper's code does, one point is
// proposed at a time and the GP hyperparameters are refitted before every
// proposal. Every speed change is measured against this in the same run.

#include <optional>

#include <open3d/geometry/PointCloud.h>
#include <open3d/pipelines/registration/Registration.h>

#include "boicp/registration/bo_icp.hpp"
#include "methods.hpp"

namespace boicp::bench {

RegistrationResult RunNaiveBoIcp(const Points& source, const Points& target,
                                 const BoIcpConfig& table_config,
                                 const RegistrationCallbacks& given_callbacks) {
  namespace reg = open3d::pipelines::registration;
  BoIcpConfig config = table_config;
  config.retry_when_doubtful = false;                  // the paper's method searches once
  config.icp_objective = IcpObjective::kPointToPoint;  // what local_icp below runs
  config.bo.batch_size = 1;
  config.bo.refit_every = 1;
  config.evaluation_points = 0;
  RegistrationCallbacks callbacks = given_callbacks;
  callbacks.local_icp = [&config](const Points& source_points, const Points& target_points,
                                  const Transform& initial) {
    const open3d::geometry::PointCloud source_cloud(source_points);
    const open3d::geometry::PointCloud target_cloud(target_points);
    return Transform(
        reg::RegistrationICP(source_cloud, target_cloud, config.EffectiveMaxCorrespondence(),
                             initial, reg::TransformationEstimationPointToPoint(false),
                             reg::ICPConvergenceCriteria(1e-6, 1e-6, config.icp_max_iterations))
            .transformation_);
  };
  return RegisterPair(source, target, config, std::nullopt, callbacks);
}

}  // namespace boicp::bench
