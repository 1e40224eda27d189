#include "boicp/registration/registration_method.hpp"

#include <chrono>
#include <cstdio>
#include <stdexcept>
#include <utility>

#include "boicp/registration/refinement.hpp"

namespace boicp {

RegistrationResult RegistrationMethod::RegisterClouds(
    PointSpan source, PointSpan target, const PairHints& hints,
    const RegistrationCallbacks& callbacks) const {
  const auto started = std::chrono::steady_clock::now();
  const std::shared_ptr<const PreparedScan> prepared_source = Prepare(source);
  const std::shared_ptr<const PreparedScan> prepared_target = Prepare(target);
  RegistrationResult result = Register(*prepared_source, *prepared_target, hints, callbacks);
  result.runtime_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  return result;
}

void MethodRegistry::Add(const std::string& name, const std::string& summary,
                         MethodFactory factory) {
  if (name.empty() || Contains(name)) {
    throw std::invalid_argument("registration method name '" + name + "' is empty or taken");
  }
  names_.push_back(name);
  entries_.emplace(name, Entry{summary, std::move(factory)});
}

bool MethodRegistry::Contains(const std::string& name) const { return entries_.count(name) > 0; }

const MethodRegistry::Entry& MethodRegistry::Find(const std::string& name) const {
  const auto found = entries_.find(name);
  if (found != entries_.end()) return found->second;
  std::string known;
  for (const std::string& n : names_) known += (known.empty() ? "" : ", ") + n;
  throw InputError("unknown registration method '" + name + "' (known: " + known + ")");
}

const std::string& MethodRegistry::Summary(const std::string& name) const {
  return Find(name).summary;
}

std::unique_ptr<const RegistrationMethod> MethodRegistry::Create(const std::string& name,
                                                                 const BoIcpConfig& config) const {
  BoIcpConfig named = config;
  named.method = name;
  return Find(name).factory(named);
}

namespace {

// A scan cropped, centred and downsampled at every level of the config's
// pyramid: what both engine methods register.
class PyramidScan final : public PreparedScan {
 public:
  explicit PyramidScan(ScanPyramid pyramid) : pyramid_(std::move(pyramid)) {}
  const ScanPyramid& pyramid() const { return pyramid_; }

  static const ScanPyramid& Of(const PreparedScan& scan) {
    const auto* pyramid = dynamic_cast<const PyramidScan*>(&scan);
    if (pyramid == nullptr) {
      throw std::invalid_argument("an engine method was given a scan another method prepared");
    }
    return pyramid->pyramid();
  }

 private:
  ScanPyramid pyramid_;
};

class PyramidMethod : public RegistrationMethod {
 public:
  explicit PyramidMethod(const BoIcpConfig& config) : config_(config) {
    if (!config_.automatic.empty()) {
      throw std::invalid_argument("a registration method needs its settings chosen beforehand");
    }
    ValidateConfig(config_);
  }

  std::shared_ptr<const PreparedScan> Prepare(PointSpan scan) const override {
    return std::make_shared<const PyramidScan>(BuildScanPyramid(scan, config_));
  }

 protected:
  const BoIcpConfig config_;
};

class BoIcpMethod final : public PyramidMethod {
 public:
  using PyramidMethod::PyramidMethod;

  std::string Describe() const override {
    return "BO-ICP preset " + config_.preset + ", " + SearchModeName(config_.mode) + ", budget " +
           BudgetName(config_.budget) + " (N_r " + std::to_string(config_.random_samples) + ", N " +
           std::to_string(config_.iterations) + " per stage)";
  }

  RegistrationResult Register(const PreparedScan& source, const PreparedScan& target,
                              const PairHints& hints,
                              const RegistrationCallbacks& callbacks) const override {
    return RegisterPair(PyramidScan::Of(source), PyramidScan::Of(target), config_, hints.prior,
                        callbacks, hints.guess);
  }
};

class IcpMethod final : public PyramidMethod {
 public:
  using PyramidMethod::PyramidMethod;

  std::string Describe() const override {
    char line[128];
    std::snprintf(line, sizeof(line),
                  "ICP from the prior, else the guess, else the identity, refined down to %.3g m",
                  config_.EffectiveRefineVoxel());
    return line;
  }

  RegistrationResult Register(const PreparedScan& source, const PreparedScan& target,
                              const PairHints& hints,
                              const RegistrationCallbacks& callbacks) const override {
    const Transform start = hints.prior.value_or(hints.guess.value_or(Transform::Identity()));
    return RefineFromStart(PyramidScan::Of(source), PyramidScan::Of(target), config_, start,
                           callbacks);
  }
};

}  // namespace

MethodRegistry CoreMethods() {
  MethodRegistry registry;
  registry.Add("bo-icp", "BO-ICP: the escalation ladder (budget auto) or the paper's fixed search",
               [](const BoIcpConfig& config) { return std::make_unique<BoIcpMethod>(config); });
  registry.Add("icp",
               "one ICP refinement from the prior, else the guess, else the identity: for scans "
               "already close",
               [](const BoIcpConfig& config) { return std::make_unique<IcpMethod>(config); });
  return registry;
}

}  // namespace boicp
