#include "methods.hpp"

#include <chrono>
#include <functional>
#include <memory>
#include <stdexcept>
#include <utility>

#include "bench_options.hpp"
#include "boicp/registration/auto_settings.hpp"
#include "dataset_config.hpp"
#include "evaluation_clock.hpp"

namespace boicp::bench {
namespace {

// A scan kept as it came: the baselines do all of their preprocessing in
// Register.
class RawScan final : public PreparedScan {
 public:
  explicit RawScan(Points points) : points_(std::move(points)) {}
  static const Points& Of(const PreparedScan& scan) {
    const auto* raw = dynamic_cast<const RawScan*>(&scan);
    if (raw == nullptr) throw std::invalid_argument("a baseline was given a prepared scan");
    return raw->points_;
  }

 private:
  Points points_;
};

using BaselineRun = std::function<RegistrationResult(const Points& source, const Points& target,
                                                     const BoIcpConfig& config,
                                                     const RegistrationCallbacks& callbacks)>;

class Baseline final : public RegistrationMethod {
 public:
  Baseline(std::string description, BoIcpConfig config, BaselineRun run)
      : description_(std::move(description)), config_(std::move(config)), run_(std::move(run)) {}

  std::string Describe() const override { return description_; }

  std::shared_ptr<const PreparedScan> Prepare(PointSpan scan) const override {
    return std::make_shared<const RawScan>(scan.ToPoints());
  }

  RegistrationResult Register(const PreparedScan& source, const PreparedScan& target,
                              const PairHints&,
                              const RegistrationCallbacks& callbacks) const override {
    return run_(RawScan::Of(source), RawScan::Of(target), config_, callbacks);
  }

 private:
  std::string description_;
  BoIcpConfig config_;
  BaselineRun run_;
};

void AddBaseline(MethodRegistry& registry, const std::string& name, const std::string& summary,
                 BaselineRun run) {
  registry.Add(name, summary, [summary, run](const BoIcpConfig& config) {
    return std::make_unique<Baseline>(summary, config, run);
  });
}

// A bench name: the registry's method it runs and the settings it runs it with.
struct BenchMethod {
  std::string name;
  std::string method;  // in BenchRegistry
  std::function<BoIcpConfig(const MethodInput&)> config;
  bool search = false;  // a BO search: reports its confidence, attempts and time split
  std::function<std::string(bool quick)> describe;
};

BoIcpConfig PaperSearch(const std::string& preset, bool six_dof, const MethodInput& input) {
  BoIcpConfig config = DatasetBoConfig(preset, input);
  if (six_dof) config.mode = SearchMode::kSixDof;
  return config;
}

std::function<std::string(bool)> Fixed(std::string text) {
  return [text = std::move(text)](bool) { return text; };
}

const std::vector<BenchMethod>& BenchMethods() {
  static const std::vector<BenchMethod> kMethods = {
      {"bo-A", "bo-icp", [](const MethodInput& in) { return PaperSearch("A", false, in); }, true,
       Fixed("core RegisterPair, preset A (N_r 10, N 20 per stage, voxel 7/6 of the dataset's), "
             "nested")},
      {"bo-B", "bo-icp", [](const MethodInput& in) { return PaperSearch("B", false, in); }, true,
       Fixed("core RegisterPair, preset B (N_r 20, N 35, voxel 7/6 of the dataset's), nested")},
      {"bo-C", "bo-icp", [](const MethodInput& in) { return PaperSearch("C", false, in); }, true,
       Fixed("core RegisterPair, preset C (N_r 30, N 60, dataset voxel), nested")},
      {"bo-C-6dof", "bo-icp", [](const MethodInput& in) { return PaperSearch("C", true, in); },
       true, Fixed("core RegisterPair, preset C, one 6-DOF search (N_r 30, N 60)")},
      {"bo-C-so3", "bo-icp",
       [](const MethodInput& in) {
         BoIcpConfig config = PaperSearch("C", false, in);
         config.rotation_coordinates = RotationCoordinates::kRotationVector;
         return config;
       },
       true,
       Fixed("core RegisterPair, preset C as bo-C, but a box holding every rotation is searched "
             "as rotation vectors (uniform initial rotations, geodesic kernel)")},
      {"bo-C-auto", "bo-icp", DatasetAutoConfig, true,
       Fixed("core RegisterPair as `boicp register` runs it with no flags: preset C, settings "
             "chosen from the pair, the escalation ladder (features, short search, full search, "
             "retry; no prior)")},
      {"naive", "naive", [](const MethodInput& in) { return PaperSearch("C", false, in); }, true,
       Fixed("core RegisterPair with preset C (as bo-C), but every search evaluation calls "
             "Open3D RegistrationICP afresh (converts the clouds, rebuilds the target kd-tree, "
             "whole search source), one proposal at a time, hyperparameters refitted every step")},
      {"icp-identity", "icp-identity",
       [](const MethodInput& in) { return DatasetTableConfig("C", in); }, false,
       Fixed("point-to-point ICP from the identity, then the shared coarse-to-fine refinement")},
      {"pyramid", "pyramid", [](const MethodInput& in) { return DatasetTableConfig("C", in); },
       false,
       [](bool quick) {
         return std::string(quick ? "nested grid, 8^d initial, top 5 refined 3x with 4^d, 300 "
                                    "score points (quick budget), ICP on the top 5"
                                  : "nested grid, 12^d initial, top 10 refined 3x with 6^d, 1000 "
                                    "score points, fit radius 3 voxels, ICP on the top 10");
       }},
      {"ransac-fpfh", "ransac-fpfh",
       [](const MethodInput& in) { return DatasetTableConfig("C", in); }, false,
       [](bool quick) {
         return std::string(
                    "Open3D RANSAC on FPFH (normals 2v, FPFH 5v, distance 1.5v, mutual filter, "
                    "edge 0.9), ") +
                (quick ? "20000 iterations (quick budget)" : "100000 iterations") +
                ", confidence 0.999, then the shared refinement";
       }},
      {"fgr", "fgr", [](const MethodInput& in) { return DatasetTableConfig("C", in); }, false,
       Fixed("Open3D FGR on FPFH (absolute scale, 1.5v), then the shared refinement")},
  };
  return kMethods;
}

const BenchMethod& FindBenchMethod(const std::string& name) {
  for (const BenchMethod& method : BenchMethods()) {
    if (method.name == name) return method;
  }
  throw UsageError("unknown method '" + name + "'");
}

double SecondsSince(std::chrono::steady_clock::time_point started) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
}

// Runs the registry's `method` with `config` on the raw pair, choosing the
// fields still automatic from the pair first, as RegisterPair does.
MethodOutput RunRegistered(const std::string& method, BoIcpConfig config, bool search,
                           const MethodInput& input) {
  EvaluationClock clock;
  const auto started = std::chrono::steady_clock::now();
  ChooseSettingsForPair(input.source, input.target, config);
  const RegistrationResult result =
      BenchRegistry(input.quick)
          .Create(method, config)
          ->RegisterClouds(input.source, input.target, {}, clock.Callbacks());
  MethodOutput output;
  output.transform = result.transform;
  output.evaluations = result.evaluations;
  output.source_points = result.source_points;
  output.target_points = result.target_points;
  output.voxel = result.config.voxel;
  if (!search) return output;
  const EvaluationClock::Split split = clock.Estimate(SecondsSince(started));
  output.confidence = result.confidence;
  output.iterations = config.iterations;
  output.features = result.features;
  output.attempts = static_cast<int>(result.attempts.size());
  for (size_t k = 1; k < result.attempts.size(); ++k)
    output.retry_s += result.attempts[k].runtime_s;
  output.answered_by = RungName(result.answered_by);
  output.attempt_details = result.attempts;
  output.icp_s = split.icp_s;
  output.model_s = split.model_s;
  return output;
}

}  // namespace

MethodRegistry BenchRegistry(bool quick) {
  MethodRegistry registry = CoreMethods();
  AddBaseline(registry, "naive", "the straightforward port of BO-ICP (Open3D ICP per evaluation)",
              RunNaiveBoIcp);
  AddBaseline(
      registry, "icp-identity", "point-to-point ICP from the identity, refined",
      [](const Points& source, const Points& target, const BoIcpConfig& config,
         const RegistrationCallbacks&) { return RunIcpFromIdentity(source, target, config); });
  AddBaseline(
      registry, "pyramid", "the paper's nested grid search, ICP on its best cells",
      [quick](const Points& source, const Points& target, const BoIcpConfig& config,
              const RegistrationCallbacks&) { return RunPyramid(source, target, config, quick); });
  AddBaseline(registry, "ransac-fpfh", "Open3D RANSAC on FPFH features, refined",
              [quick](const Points& source, const Points& target, const BoIcpConfig& config,
                      const RegistrationCallbacks&) {
                return RunRansacFpfh(source, target, config, quick);
              });
  AddBaseline(registry, "fgr", "Open3D fast global registration on FPFH features, refined",
              [](const Points& source, const Points& target, const BoIcpConfig& config,
                 const RegistrationCallbacks&) { return RunFastGlobal(source, target, config); });
  return registry;
}

const std::vector<std::string>& MethodNames() {
  static const std::vector<std::string> kNames = [] {
    std::vector<std::string> names;
    for (const BenchMethod& method : BenchMethods()) names.push_back(method.name);
    return names;
  }();
  return kNames;
}

MethodOutput RunMethod(const std::string& name, const MethodInput& input) {
  const BenchMethod& method = FindBenchMethod(name);
  return RunRegistered(method.method, method.config(input), method.search, input);
}

MethodOutput RunBoIcpWithConfig(const BoIcpConfig& config, const MethodInput& input) {
  return RunRegistered(kDefaultMethod, config, true, input);
}

std::vector<std::string> DescribeMethods(const std::vector<std::string>& names, bool quick) {
  std::vector<std::string> lines;
  for (const std::string& name : names) {
    const BenchMethod& method = FindBenchMethod(name);
    std::string line = "`" + name + "`: " + method.describe(quick);
    if (quick && method.search) line += " (quick budget: N_r and N capped at 10)";
    lines.push_back(line);
  }
  return lines;
}

}  // namespace boicp::bench
