#include "boicp/mapping/pose_graph.hpp"

#include <algorithm>
#include <cstdio>
#include <deque>
#include <numeric>
#include <optional>
#include <string>

#include <open3d/pipelines/registration/GlobalOptimization.h>
#include <open3d/pipelines/registration/GlobalOptimizationConvergenceCriteria.h>
#include <open3d/pipelines/registration/GlobalOptimizationMethod.h>
#include <open3d/pipelines/registration/PoseGraph.h>

#include "boicp/mapping/chain_uncertainty.hpp"
#include "boicp/mapping/robust_pose_graph.hpp"

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
// under `poses`: r^2 = e^T I e, with e its misfit (ConstraintMisfit) and I
// the edge's full information. 1 = the poses agree with it exactly.
double AgreementWithPoses(const PairConstraint& c, const std::vector<Transform>& poses, double mu) {
  const Eigen::Matrix<double, 6, 1> e = ConstraintMisfit(c, poses);
  const double r2 = e.dot(c.information * e);
  if (!(mu > 0.0)) return r2 > 0.0 ? 0.0 : 1.0;
  const double w = mu / (mu + r2);
  return w * w;
}

// `c` with its information scaled by its weight, as the optimisation uses it.
PairConstraint Weighted(PairConstraint c) {
  c.information *= EdgeWeight(c);
  return c;
}

std::vector<PairConstraint> Weighted(std::vector<PairConstraint> constraints) {
  for (PairConstraint& c : constraints) c = Weighted(c);
  return constraints;
}

std::string FormatChi2(double chi2) {
  char text[32];
  std::snprintf(text, sizeof(text), "%.3g", chi2);
  return text;
}

// How a constraint enters the optimisation.
enum class EdgeRole {
  kTree,           // certain: a spanning-tree edge
  kCertainLoop,    // certain: a trusted loop closure the chain agrees with
  kUncertainLoop,  // Open3D's line process may weigh it down and prune it
  kLeftOut,
};

// Open3D's pose graph over the constraints not left out, each edge's
// information scaled by its weight. Kept (and the final line-process
// weight) per constraint; false for those left out or pruned.
OptimizedPoses OptimizeEdges(const std::vector<Transform>& initial,
                             const std::vector<PairConstraint>& constraints,
                             const std::vector<EdgeRole>& roles, const PoseGraphOptions& options) {
  reg::PoseGraph graph;
  for (const Transform& pose : initial) graph.nodes_.emplace_back(pose);
  std::vector<size_t> edge_of;  // graph edge -> constraint
  for (size_t e = 0; e < constraints.size(); ++e) {
    if (roles[e] == EdgeRole::kLeftOut) continue;
    const PairConstraint& c = constraints[e];
    const double weight = EdgeWeight(c);
    const bool uncertain = roles[e] == EdgeRole::kUncertainLoop;
    // Open3D requires confidence 1 on certain edges; an uncertain loop
    // closure's line process starts from the pair's confidence.
    graph.edges_.emplace_back(c.pair.source, c.pair.target, c.T_target_source,
                              InformationMatrix(c.information * weight), uncertain,
                              uncertain ? weight : 1.0);
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
  out.left_out_because.assign(constraints.size(), "");
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

// The robust optimisation (SolveRobustPoseGraph) over the constraints not
// left out, each information scaled by its weight; the loss's weight at the
// solution stands for the line process.
OptimizedPoses OptimizeRobustly(const std::vector<Transform>& initial,
                                const std::vector<PairConstraint>& constraints,
                                const std::vector<EdgeRole>& roles) {
  std::vector<PairConstraint> edges;
  std::vector<size_t> edge_of;
  for (size_t e = 0; e < constraints.size(); ++e) {
    if (roles[e] == EdgeRole::kLeftOut) continue;
    edges.push_back(Weighted(constraints[e]));
    edge_of.push_back(e);
  }
  RobustPoseGraphSolution solution = SolveRobustPoseGraph(initial, edges);
  OptimizedPoses out;
  out.poses = std::move(solution.poses);
  out.kept.assign(constraints.size(), false);
  out.line_process.assign(constraints.size(), 0.0);
  out.left_out_because.assign(constraints.size(), "");
  for (size_t k = 0; k < edge_of.size(); ++k) {
    out.kept[edge_of[k]] = true;
    out.line_process[edge_of[k]] = solution.weights[k];
  }
  return out;
}

}  // namespace

InformationMatrix CalibratedInformation(const InformationMatrix& information, double pair_error) {
  const double variance = pair_error * pair_error;
  // A direction no inlier constrains keeps a little information, so the
  // graph stays well posed; the pair then barely pulls along it.
  const InformationMatrix floor = InformationMatrix::Identity() * (kMinEdgeWeight / variance);
  const double inliers = information.bottomRightCorner<3, 3>().trace() / 3.0;
  if (!(inliers > 0.0)) return floor;
  return information / (inliers * variance) + floor;
}

bool IsDoubtfulEdge(const PairConstraint& constraint) {
  return constraint.confidence < kTrustedFrom;
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

  // Kruskal: trusted constraints in the given order, then doubtful ones
  // from the most confident; the first constraint joining two parts wins.
  std::vector<size_t> order(constraints.size());
  std::iota(order.begin(), order.end(), size_t{0});
  std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) {
    const bool doubtful_a = IsDoubtfulEdge(constraints[a]);
    if (doubtful_a != IsDoubtfulEdge(constraints[b])) return !doubtful_a;
    return doubtful_a && constraints[a].confidence > constraints[b].confidence;
  });
  std::vector<int> parent(static_cast<size_t>(num_scans));
  std::iota(parent.begin(), parent.end(), 0);
  for (const size_t e : order) {
    const PairIndex& p = constraints[e].pair;
    const int a = FindRoot(parent, p.source), b = FindRoot(parent, p.target);
    if (a == b) {
      ++out.loop_closures;
      continue;
    }
    parent[a] = b;
    out.in_tree[e] = true;
  }

  out.poses.assign(static_cast<size_t>(num_scans), Transform::Identity());
  out.poses[0] = anchor;
  const std::vector<TreeStep> walk = WalkTree(num_scans, constraints, out.in_tree);
  std::vector<bool> placed(static_cast<size_t>(num_scans), false);
  placed[0] = true;
  for (const TreeStep& step : walk) {
    const PairConstraint& c = constraints[step.edge];
    // T_map_source = T_map_target * T_target_source, and its inverse for
    // walking from the source to the target.
    const Transform& from = out.poses[static_cast<size_t>(step.from)];
    out.poses[static_cast<size_t>(step.scan)] = c.pair.target == step.from
                                                    ? Transform(from * c.T_target_source)
                                                    : Transform(from * c.T_target_source.inverse());
    placed[static_cast<size_t>(step.scan)] = true;
  }
  for (int i = 0; i < num_scans; ++i) {
    if (!placed[static_cast<size_t>(i)]) {
      throw InputError("pose chain: no chain of registered pairs reaches scan " +
                       std::to_string(i) + " from scan 0");
    }
  }
  return out;
}

std::vector<TreeStep> WalkTree(int num_scans, const std::vector<PairConstraint>& constraints,
                               const std::vector<bool>& in_tree) {
  std::vector<std::vector<size_t>> edges_of(static_cast<size_t>(std::max(num_scans, 0)));
  for (size_t e = 0; e < constraints.size() && e < in_tree.size(); ++e) {
    if (!in_tree[e]) continue;
    edges_of[static_cast<size_t>(constraints[e].pair.source)].push_back(e);
    edges_of[static_cast<size_t>(constraints[e].pair.target)].push_back(e);
  }
  std::vector<TreeStep> walk;
  if (num_scans < 1) return walk;
  std::vector<bool> reached(static_cast<size_t>(num_scans), false);
  reached[0] = true;
  std::deque<int> queue{0};
  while (!queue.empty()) {
    const int at = queue.front();
    queue.pop_front();
    for (size_t e : edges_of[static_cast<size_t>(at)]) {
      const PairIndex& p = constraints[e].pair;
      const int next = p.target == at ? p.source : p.target;
      if (reached[static_cast<size_t>(next)]) continue;
      reached[static_cast<size_t>(next)] = true;
      walk.push_back({next, at, e});
      queue.push_back(next);
    }
  }
  return walk;
}

OptimizedPoses OptimizePoseGraph(const std::vector<Transform>& initial,
                                 const std::vector<PairConstraint>& given,
                                 const std::vector<bool>& in_tree,
                                 const PoseGraphOptions& options) {
  const bool calibrated = options.pair_error > 0.0;
  std::vector<PairConstraint> constraints = given;
  for (size_t e = 0; e < constraints.size(); ++e) {
    const PairIndex& p = constraints[e].pair;
    const int n = static_cast<int>(initial.size());
    if (p.source < 0 || p.source >= n || p.target < 0 || p.target >= n) {
      throw InputError("pose graph: constraint " + std::to_string(e) +
                       " has an index out of range");
    }
    if (calibrated) {
      constraints[e].information =
          CalibratedInformation(constraints[e].information, options.pair_error);
    }
  }

  // A doubtful loop closure has no evidence of its own: it joins only when
  // the poses chained from the tree (trusted pairs first) agree with it at
  // full weight. Scaled down first, a wrong one would look consistent.
  // A trusted one, with calibrated information, joins as a certain edge when
  // it disagrees with the chain by no more than the chain and the pair may
  // err together (ChainUncertainty): a right loop closing a drifted chain
  // disagrees with it by the drift, which the line process would take for
  // an outlier.
  const double mu = LineProcessScale(constraints, options);
  std::vector<EdgeRole> roles(constraints.size(), EdgeRole::kTree);
  std::vector<std::string> reasons(constraints.size());
  std::optional<ChainUncertainty> chain;
  for (size_t e = 0; e < constraints.size(); ++e) {
    if (!IsLoopClosure(in_tree, e)) continue;
    const PairConstraint& c = constraints[e];
    if (IsDoubtfulEdge(c)) {
      const bool agrees = AgreementWithPoses(c, initial, mu) >= options.doubtful_keep_threshold;
      roles[e] = agrees ? EdgeRole::kUncertainLoop : EdgeRole::kLeftOut;
      if (!agrees) reasons[e] = "doubtful, and the chained poses disagree with it";
      continue;
    }
    if (!calibrated) {
      roles[e] = EdgeRole::kUncertainLoop;
      continue;
    }
    if (!chain) chain.emplace(initial, Weighted(constraints), in_tree);
    const double chi2 = chain->LoopDisagreement(Weighted(c));
    roles[e] = chi2 <= kLoopAgreementChi2 ? EdgeRole::kCertainLoop : EdgeRole::kLeftOut;
    if (roles[e] == EdgeRole::kLeftOut) {
      reasons[e] = "disagrees with the chained poses beyond their uncertainty (chi-square " +
                   FormatChi2(chi2) + ")";
    }
  }

  // Loop closures that each agree with the chain may still contradict one
  // another: after the optimisation, the one that fits the result worst is
  // left out, until every certain loop closure (with calibrated information:
  // every loop closure) fits.
  for (;;) {
    OptimizedPoses out = calibrated ? OptimizeRobustly(initial, constraints, roles)
                                    : OptimizeEdges(initial, constraints, roles, options);
    size_t worst = constraints.size();
    double worst_chi2 = kLoopAgreementChi2;
    for (size_t e = 0; e < constraints.size(); ++e) {
      const bool loop = roles[e] == EdgeRole::kCertainLoop ||
                        (calibrated && roles[e] == EdgeRole::kUncertainLoop);
      if (!loop) continue;
      const Eigen::Matrix<double, 6, 1> misfit = ConstraintMisfit(constraints[e], out.poses);
      const double chi2 = misfit.dot(Weighted(constraints[e]).information * misfit);
      if (chi2 > worst_chi2) {
        worst = e;
        worst_chi2 = chi2;
      }
    }
    if (worst == constraints.size()) {
      for (size_t e = 0; e < constraints.size(); ++e) {
        if (!reasons[e].empty()) {
          out.left_out_because[e] = reasons[e];
        } else if (!out.kept[e]) {
          out.left_out_because[e] = "pruned by the optimisation as an outlier";
        }
      }
      return out;
    }
    roles[worst] = EdgeRole::kLeftOut;
    reasons[worst] = "contradicts the other loop closures (chi-square " + FormatChi2(worst_chi2) +
                     " after the optimisation)";
  }
}

}  // namespace boicp
