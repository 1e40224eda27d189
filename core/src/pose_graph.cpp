#include "boicp/pose_graph.hpp"

#include <deque>
#include <numeric>
#include <string>

#include <open3d/geometry/PointCloud.h>
#include <open3d/pipelines/registration/GlobalOptimization.h>
#include <open3d/pipelines/registration/GlobalOptimizationConvergenceCriteria.h>
#include <open3d/pipelines/registration/GlobalOptimizationMethod.h>
#include <open3d/pipelines/registration/PoseGraph.h>
#include <open3d/pipelines/registration/Registration.h>

namespace boicp {
namespace {

namespace reg = open3d::pipelines::registration;

int FindRoot(std::vector<int>& parent, int i) {
  while (parent[i] != i) {
    parent[i] = parent[parent[i]];
    i = parent[i];
  }
  return i;
}

open3d::geometry::PointCloud ToOpen3d(const Points& points) {
  open3d::geometry::PointCloud cloud;
  cloud.points_ = points;
  return cloud;
}

}  // namespace

ChainedPoses ChainPoses(int num_scans, const std::vector<PairConstraint>& constraints,
                        const Transform& anchor) {
  ChainedPoses out;
  out.in_tree.assign(constraints.size(), false);
  if (num_scans < 1) return out;

  // Kruskal in the given order: the first constraint joining two parts wins.
  std::vector<int> parent(static_cast<size_t>(num_scans));
  std::iota(parent.begin(), parent.end(), 0);
  std::vector<std::vector<size_t>> edges_of(static_cast<size_t>(num_scans));
  for (size_t e = 0; e < constraints.size(); ++e) {
    const PairIndex& p = constraints[e].pair;
    if (p.source < 0 || p.source >= num_scans || p.target < 0 || p.target >= num_scans) {
      throw InputError("pose chain: constraint " + std::to_string(e) +
                       " has an index out of range");
    }
    const int a = FindRoot(parent, p.source), b = FindRoot(parent, p.target);
    if (a == b) {
      ++out.loop_closures;
      continue;
    }
    parent[a] = b;
    out.in_tree[e] = true;
    edges_of[static_cast<size_t>(p.source)].push_back(e);
    edges_of[static_cast<size_t>(p.target)].push_back(e);
  }

  // Breadth-first from scan 0 along tree edges, in whichever direction the
  // edge points.
  std::vector<bool> placed(static_cast<size_t>(num_scans), false);
  out.poses.assign(static_cast<size_t>(num_scans), Transform::Identity());
  out.poses[0] = anchor;
  placed[0] = true;
  std::deque<int> queue{0};
  while (!queue.empty()) {
    const int at = queue.front();
    queue.pop_front();
    for (size_t e : edges_of[static_cast<size_t>(at)]) {
      const PairConstraint& c = constraints[e];
      const bool at_is_target = c.pair.target == at;
      const int next = at_is_target ? c.pair.source : c.pair.target;
      if (placed[static_cast<size_t>(next)]) continue;
      // T_map_source = T_map_target * T_target_source, and its inverse for
      // walking from the source to the target.
      out.poses[static_cast<size_t>(next)] =
          at_is_target
              ? Transform(out.poses[static_cast<size_t>(at)] * c.T_target_source)
              : Transform(out.poses[static_cast<size_t>(at)] * c.T_target_source.inverse());
      placed[static_cast<size_t>(next)] = true;
      queue.push_back(next);
    }
  }
  for (int i = 0; i < num_scans; ++i) {
    if (!placed[static_cast<size_t>(i)]) {
      throw InputError("pose chain: no chain of registered pairs reaches scan " +
                       std::to_string(i) + " from scan 0");
    }
  }
  return out;
}

OptimizedPoses OptimizePoseGraph(const std::vector<Transform>& initial,
                                 const std::vector<PairConstraint>& constraints,
                                 const std::vector<bool>& in_tree,
                                 const PoseGraphOptions& options) {
  reg::PoseGraph graph;
  for (const Transform& pose : initial) graph.nodes_.emplace_back(pose);
  for (size_t e = 0; e < constraints.size(); ++e) {
    const PairConstraint& c = constraints[e];
    const bool loop_closure = e >= in_tree.size() || !in_tree[e];
    graph.edges_.emplace_back(c.pair.source, c.pair.target, c.T_target_source, c.information,
                              /*uncertain=*/loop_closure, /*confidence=*/1.0);
  }
  reg::GlobalOptimizationConvergenceCriteria criteria;
  criteria.max_iteration_ = options.max_iterations;
  const reg::GlobalOptimizationOption option(options.max_correspondence_distance,
                                             options.edge_prune_threshold,
                                             options.preference_loop_closure,
                                             /*reference_node=*/0);
  try {
    reg::GlobalOptimization(graph, reg::GlobalOptimizationLevenbergMarquardt(), criteria, option);
  } catch (const std::exception& e) {
    throw std::runtime_error(std::string("pose-graph optimisation failed: ") + e.what());
  }

  OptimizedPoses out;
  for (const auto& node : graph.nodes_) out.poses.emplace_back(node.pose_);
  // Open3D removes pruned edges; match the survivors back to the input.
  std::vector<std::pair<int, int>> surviving;
  for (const auto& edge : graph.edges_) {
    surviving.emplace_back(edge.source_node_id_, edge.target_node_id_);
  }
  out.kept.assign(constraints.size(), false);
  size_t next = 0;
  for (size_t e = 0; e < constraints.size() && next < surviving.size(); ++e) {
    if (surviving[next] == std::make_pair(constraints[e].pair.source, constraints[e].pair.target)) {
      out.kept[e] = true;
      ++next;
    }
  }
  return out;
}

InformationMatrix PairInformation(const Points& source, const Points& target,
                                  const Transform& T_target_source, double max_distance) {
  const open3d::geometry::PointCloud source_cloud = ToOpen3d(source);
  const open3d::geometry::PointCloud target_cloud = ToOpen3d(target);
  try {
    return reg::GetInformationMatrixFromPointClouds(source_cloud, target_cloud, max_distance,
                                                    T_target_source);
  } catch (const std::exception& e) {
    throw std::runtime_error(std::string("information matrix: ") + e.what());
  }
}

}  // namespace boicp
