#include "methods.hpp"

#include "bench_options.hpp"

namespace boicp::bench {

const std::vector<std::string>& MethodNames() {
  static const std::vector<std::string> kNames = {
      "bo-A",  "bo-B",         "bo-C",    "bo-C-6dof",   "bo-C-auto",
      "naive", "icp-identity", "pyramid", "ransac-fpfh", "fgr"};
  return kNames;
}

MethodOutput RunMethod(const std::string& name, const MethodInput& input) {
  if (name == "bo-A") return RunBoIcp("A", false, input);
  if (name == "bo-B") return RunBoIcp("B", false, input);
  if (name == "bo-C") return RunBoIcp("C", false, input);
  if (name == "bo-C-6dof") return RunBoIcp("C", true, input);
  if (name == "bo-C-auto") return RunBoIcpAuto(input);
  if (name == "naive") return RunNaiveBoIcp(input);
  if (name == "icp-identity") return RunIcpFromIdentity(input);
  if (name == "pyramid") return RunPyramid(input);
  if (name == "ransac-fpfh") return RunRansacFpfh(input);
  if (name == "fgr") return RunFastGlobal(input);
  throw UsageError("unknown method '" + name + "'");
}

std::vector<std::string> DescribeMethods(const std::vector<std::string>& names, bool quick) {
  std::vector<std::string> lines;
  for (const std::string& name : names) {
    std::string line = "`" + name + "`: ";
    if (name == "bo-A") {
      line +=
          "core RegisterPair, preset A (N_r 10, N 20 per stage, voxel 7/6 of the dataset's), "
          "nested";
    } else if (name == "bo-B") {
      line += "core RegisterPair, preset B (N_r 20, N 35, voxel 7/6 of the dataset's), nested";
    } else if (name == "bo-C") {
      line += "core RegisterPair, preset C (N_r 30, N 60, dataset voxel), nested";
    } else if (name == "bo-C-6dof") {
      line += "core RegisterPair, preset C, one 6-DOF search (N_r 30, N 60)";
    } else if (name == "bo-C-auto") {
      line +=
          "core RegisterPair as `boicp register` runs it with no flags: preset C, settings "
          "chosen from the pair, the escalation ladder (features, short search, full search, "
          "retry; no prior)";
    } else if (name == "naive") {
      line +=
          "core RegisterPair with preset C (as bo-C), but every search evaluation calls Open3D "
          "RegistrationICP afresh (converts the clouds, rebuilds the target kd-tree, whole "
          "search source), one proposal at a time, hyperparameters refitted every step";
    } else if (name == "icp-identity") {
      line += "point-to-point ICP from the identity, then the shared coarse-to-fine refinement";
    } else if (name == "pyramid") {
      line += quick ? "nested grid, 8^d initial, top 5 refined 3x with 4^d, 300 score points "
                      "(quick budget), ICP on the top 5"
                    : "nested grid, 12^d initial, top 10 refined 3x with 6^d, 1000 score points, "
                      "fit radius 3 voxels, ICP on the top 10";
    } else if (name == "ransac-fpfh") {
      line += std::string(
                  "Open3D RANSAC on FPFH (normals 2v, FPFH 5v, distance 1.5v, mutual "
                  "filter, edge 0.9), ") +
              (quick ? "20000 iterations (quick budget)" : "100000 iterations") +
              ", confidence 0.999, then the shared refinement";
    } else if (name == "fgr") {
      line += "Open3D FGR on FPFH (absolute scale, 1.5v), then the shared refinement";
    }
    const bool bayesian = name.rfind("bo-", 0) == 0 || name == "naive";
    if (quick && bayesian) line += " (quick budget: N_r and N capped at 10)";
    lines.push_back(line);
  }
  return lines;
}

}  // namespace boicp::bench
