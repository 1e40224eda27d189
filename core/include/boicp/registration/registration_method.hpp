#pragma once
// One interface for the ways a pair of scans can be registered, and a
// registry of them by name: `boicp register`, the map pipeline, the daemon
// and the bench all pick a method from a registry, and a map's pairs share
// each scan's preparation whatever the method.

#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "boicp/registration/bo_icp.hpp"
#include "boicp/registration/config.hpp"
#include "boicp/util/point_span.hpp"
#include "boicp/util/types.hpp"

namespace boicp {

/// A scan as one method prepared it (cropped, downsampled, indexed), built
/// once and shared by every pair the scan is in. Only the method that made
/// it, or one of the same name and settings, reads it.
class PreparedScan {
 public:
  virtual ~PreparedScan() = default;
};

/// What a pair brings besides its two scans; transforms are T_target_source.
struct PairHints {
  /// Where the pair is believed to be (odometry, a pose graph): a search is
  /// centred on it.
  std::optional<Transform> prior;
  /// A start to try before searching that does not move the search (identity
  /// for consecutive scans of a drive).
  std::optional<Transform> guess;
};

/// A way to register pairs, with its settings fixed when built. Every call
/// is thread-safe, so one instance serves every pair of a batch.
class RegistrationMethod {
 public:
  virtual ~RegistrationMethod() = default;

  /// One line for logs and reports: what the method runs, with its budget.
  virtual std::string Describe() const = 0;

  /// `scan` (raw points in its sensor frame, metres) as Register needs it.
  /// Depends on the settings but not on the seed, so a method built for
  /// another pair of the batch registers it too. Throws InputError when
  /// cropping leaves nothing to register.
  virtual std::shared_ptr<const PreparedScan> Prepare(PointSpan scan) const = 0;

  /// Registers `source` onto `target`, both prepared by a method of this
  /// name and settings. result.transform is T_target_source. Throws
  /// Cancelled when callbacks.stop_requested fires, InputError for input the
  /// method cannot register, std::invalid_argument for a scan another
  /// method prepared.
  virtual RegistrationResult Register(const PreparedScan& source, const PreparedScan& target,
                                      const PairHints& hints,
                                      const RegistrationCallbacks& callbacks = {}) const = 0;

  /// Prepare, then Register; runtime_s covers both.
  RegistrationResult RegisterClouds(PointSpan source, PointSpan target, const PairHints& hints = {},
                                    const RegistrationCallbacks& callbacks = {}) const;
};

/// Builds a method from final settings (config.automatic empty, valid);
/// config.method is the name it was asked for.
using MethodFactory = std::function<std::unique_ptr<const RegistrationMethod>(const BoIcpConfig&)>;

/// Methods by name, in the order they were added.
class MethodRegistry {
 public:
  /// Adds `name` with a one-line `summary` for help texts. Throws
  /// std::invalid_argument when the name is taken or empty.
  void Add(const std::string& name, const std::string& summary, MethodFactory factory);

  bool Contains(const std::string& name) const;
  /// Throws InputError listing the known names when `name` is not one.
  void Require(const std::string& name) const { Find(name); }
  const std::vector<std::string>& Names() const { return names_; }
  /// Throws InputError listing the known names for an unknown one.
  const std::string& Summary(const std::string& name) const;

  /// The method `name` with `config`'s settings. Throws InputError listing
  /// the known names for an unknown one.
  std::unique_ptr<const RegistrationMethod> Create(const std::string& name,
                                                   const BoIcpConfig& config) const;

 private:
  struct Entry {
    std::string summary;
    MethodFactory factory;
  };
  const Entry& Find(const std::string& name) const;

  std::vector<std::string> names_;
  std::map<std::string, Entry> entries_;
};

/// The engine's own methods: "bo-icp" (BO-ICP, the ladder or the paper's
/// fixed search as config.budget says) and "icp" (one refinement from the
/// prior, else the guess, else the identity; RefineFromStart). Both prepare
/// a scan as BuildScanPyramid does, so their prepared scans are
/// interchangeable.
MethodRegistry CoreMethods();

}  // namespace boicp
