#include "boicp/mapping/pose_graph.hpp"

#include <algorithm>
#include <deque>
#include <numeric>
#include <string>

#include <open3d/pipelines/registration/GlobalOptimization.h>
#include <open3d/pipelines/registration/GlobalOptimizationConvergenceCriteria.h>
#include <open3d/pipelines/registration/GlobalOptimizationMethod.h>
#include <open3d/pipelines/registration/PoseGraph.h>

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

bool IsLoopClosure(const std::vector<bool>& in_tree, size_t e) {
  return e >= in_tree.size() || !in_tree[e];
}

// The weight of an edge in the optimisation: its confidence, floored so the
// system stays well posed.
double EdgeWeight(const PairConstraint& c) { return std::clamp(c.confidence, kMinEdgeWeight, 1.0); }

// The line-process scale mu of Open3D's optimisation (Choi et al. 2015,
// section 5): preference * max_correspondence_distance^2 * the mean
// correspondence count, information(5, 5).
double LineProcessScale(const std::vector<PairConstraint>& constraints,
                        const PoseGraphOptions& options) {
  if (constraints.empty()) return 0.0;
  double correspondences = 0.0;
  for (const PairConstraint& c : constraints) correspondences += c.information(5, 5);
  return options.preference_loop_closure * options.max_correspondence_distance *
         options.max_correspondence_distance * correspondences /
         static_cast<double>(constraints.size());
}

// The line-process weight (mu / (mu + r^2))^2 a loop closure starts with
// under `poses`: r^2 = e^T I e, with e Open3D's linearised misalignment
// (rotation first) of T_target_source against the poses and I the edge's
// full information. 1 = the poses agree with it exactly.
double AgreementWithPoses(const PairConstraint& c, const std::vector<Transform>& poses, double mu) {
  const Eigen::Matrix4d misfit =
      (c.T_target_source.inverse() * poses[static_cast<size_t>(c.pair.target)].inverse() *
       poses[static_cast<size_t>(c.pair.source)])
          .matrix();
  Eigen::Matrix<double, 6, 1> e;
  e << (misfit(2, 1) - misfit(1, 2)) / 2.0, (misfit(0, 2) - misfit(2, 0)) / 2.0,
      (misfit(1, 0) - misfit(0, 1)) / 2.0, misfit(0, 3), misfit(1, 3), misfit(2, 3);
  const double r2 = e.dot(c.information * e);
  if (!(mu > 0.0)) return r2 > 0.0 ? 0.0 : 1.0;
  const double w = mu / (mu + r2);
  return w * w;
}

// Open3D's pose graph over the active constraints, each edge's information
// scaled by its weight. Kept (and the final line-process weight) per
// constraint; false for inactive or pruned ones.
OptimizedPoses OptimizeActiveEdges(const std::vector<Transform>& initial,
                                   const std::vector<PairConstraint>& constraints,
                                   const std::vector<bool>& in_tree,
                                   const std::vector<bool>& active,
                                   const PoseGraphOptions& options) {
  reg::PoseGraph graph;
  for (const Transform& pose : initial) graph.nodes_.emplace_back(pose);
  std::vector<size_t> edge_of;  // graph edge -> constraint
  for (size_t e = 0; e < constraints.size(); ++e) {
    if (!active[e]) continue;
    const PairConstraint& c = constraints[e];
    const double weight = EdgeWeight(c);
    const bool loop_closure = IsLoopClosure(in_tree, e);
    // Open3D requires confidence 1 on certain (tree) edges; a loop closure's
    // line process starts from the pair's confidence.
    graph.edges_.emplace_back(c.pair.source, c.pair.target, c.T_target_source,
                              InformationMatrix(c.information * weight),
                              /*uncertain=*/loop_closure, loop_closure ? weight : 1.0);
    edge_of.push_back(e);
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
  // Open3D removes pruned edges and keeps the others in order; match the
  // survivors back to the input.
  out.kept.assign(constraints.size(), false);
  out.line_process.assign(constraints.size(), 0.0);
  size_t next = 0;
  for (const auto& edge : graph.edges_) {
    while (next < edge_of.size() && std::make_pair(edge.source_node_id_, edge.target_node_id_) !=
                                        std::make_pair(constraints[edge_of[next]].pair.source,
                                                       constraints[edge_of[next]].pair.target)) {
      ++next;
    }
    if (next == edge_of.size()) break;
    out.kept[edge_of[next]] = true;
    out.line_process[edge_of[next]] = edge.confidence_;
    ++next;
  }
  return out;
}

}  // namespace

bool IsDoubtfulEdge(const PairConstraint& constraint) {
  return constraint.confidence < kDoubtfulBelow;
}

ChainedPoses ChainPoses(int num_scans, const std::vector<PairConstraint>& constraints,
                        const Transform& anchor) {
  ChainedPoses out;
  out.in_tree.assign(constraints.size(), false);
  if (num_scans < 1) return out;
  for (size_t e = 0; e < constraints.size(); ++e) {
    const PairIndex& p = constraints[e].pair;
    if (p.source < 0 || p.source >= num_scans || p.target < 0 || p.target >= num_scans) {
      throw InputError("pose chain: constraint " + std::to_string(e) +
                       " has an index out of range");
    }
  }

  // Kruskal in the given order, trusted constraints before doubtful ones:
  // the first constraint joining two parts wins.
  std::vector<int> parent(static_cast<size_t>(num_scans));
  std::iota(parent.begin(), parent.end(), 0);
  std::vector<std::vector<size_t>> edges_of(static_cast<size_t>(num_scans));
  for (const bool doubtful_pass : {false, true}) {
    for (size_t e = 0; e < constraints.size(); ++e) {
      if (IsDoubtfulEdge(constraints[e]) != doubtful_pass) continue;
      const PairIndex& p = constraints[e].pair;
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
  // A doubtful loop closure has no evidence of its own: it joins only when
  // the poses chained from the tree (trusted pairs first) agree with it at
  // full weight. Scaled down first, a wrong one would look consistent.
  const double mu = LineProcessScale(constraints, options);
  std::vector<bool> active(constraints.size(), true);
  for (size_t e = 0; e < constraints.size(); ++e) {
    const PairIndex& p = constraints[e].pair;
    const int n = static_cast<int>(initial.size());
    if (p.source < 0 || p.source >= n || p.target < 0 || p.target >= n) {
      throw InputError("pose graph: constraint " + std::to_string(e) +
                       " has an index out of range");
    }
    if (IsLoopClosure(in_tree, e) && IsDoubtfulEdge(constraints[e])) {
      active[e] =
          AgreementWithPoses(constraints[e], initial, mu) >= options.doubtful_keep_threshold;
    }
  }
  return OptimizeActiveEdges(initial, constraints, in_tree, active, options);
}

}  // namespace boicp
