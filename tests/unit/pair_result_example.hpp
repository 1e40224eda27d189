#pragma once
// A pair result with every field away from its default, for the conversion tests.

#include <Eigen/Geometry>

#include "boicp/mapping/pair_result.hpp"

namespace boicp {

inline PairResult ExamplePairResult() {
  PairResult r;
  r.pair = {3, 7};
  r.transform = Transform::Identity();
  r.transform.topLeftCorner<3, 3>() =
      Eigen::AngleAxisd(0.3, Eigen::Vector3d(0.0, 0.6, 0.8)).toRotationMatrix();
  r.transform.topRightCorner<3, 1>() = Eigen::Vector3d(1.5, -2.25, 0.125);
  r.objective = 0.031;
  r.fitness = 0.82;
  r.inlier_rmse = 0.044;
  r.confidence = 0.37;
  r.doubtful = true;
  r.overlap = 0.66;
  r.search_reach = 0.21;
  r.answered_by = Rung::kShortSearch;
  r.evaluations = 41;
  r.runtime_s = 1.75;
  r.seed = 18446744073709551557ull;
  for (int i = 0; i < 6; ++i) {
    for (int j = 0; j < 6; ++j) r.information(i, j) = 10.0 * i + j + 0.5;
  }
  r.unconstrained = std::vector<FreeSlide>{{Eigen::Vector3d(0.6, 0.8, 0.0), 0.004, 2.5},
                                           {Eigen::Vector3d(0.0, 0.0, 1.0), 0.001, 0.75}};
  r.in_graph = false;
  r.finished_at = 1764931200.25;
  return r;
}

}  // namespace boicp
