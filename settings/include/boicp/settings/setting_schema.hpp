#pragma once
// The one description of every registration and map setting: its name in
// each front end (CLI flag, run.json key, boicp.v1 proto field), its help
// text, where its value lives and what a request to the daemon may give it.
// Flags, run.json, the settings-as-used JSON (register --json, pair files),
// the proto conversions, the daemon's request limits and the bench are all
// generated from this table, so a setting added here reaches every front end
// at once. BoIcpConfig fields missing from the table (finish_icp_iterations,
// refine_max_iterations, refine_candidates, refine_source_points,
// inlier_distance, retry_voxel, rotation_coordinates, bo) are engine tuning that no front end and
// not the API takes.

#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include <Eigen/Core>

#include "boicp/registration/config.hpp"
#include "boicp/settings/requested_settings.hpp"

namespace boicp::settings {

/// The front ends that may take a setting, as bits.
enum Frontend : unsigned {
  kRegister = 1u << 0,  // boicp register
  kMap = 1u << 1,       // boicp map (and run.json)
  kSubmit = 1u << 2,    // boicp submit
  kBench = 1u << 3,     // boicp-bench
};

/// A setting that always has a value (the preset, the mode, the seed, switches).
template <typename T>
struct PlainBinding {
  T RequestedSettings::*requested;
};

/// An optional override. When `config` is set, ConfigFromSettings copies a
/// given value there and marks the field set; `effective` (when set) reads
/// the value as used, with its "0 = auto" rule resolved.
template <typename T>
struct OptionalBinding {
  std::optional<T> RequestedSettings::*requested;
  T BoIcpConfig::*config = nullptr;
  T (BoIcpConfig::*effective)() const = nullptr;
};

using SettingBinding =
    std::variant<PlainBinding<std::string>, PlainBinding<uint64_t>, PlainBinding<bool>,
                 OptionalBinding<double>, OptionalBinding<int>, OptionalBinding<uint64_t>,
                 OptionalBinding<Eigen::Vector3d>>;

/// True for the PlainBinding alternatives of SettingBinding.
template <typename Binding>
inline constexpr bool kIsPlainBinding = false;
template <typename T>
inline constexpr bool kIsPlainBinding<PlainBinding<T>> = true;

/// The type of the value a binding holds (T of PlainBinding<T> or OptionalBinding<T>).
template <typename Binding>
struct BindingValue;
template <typename T>
struct BindingValue<PlainBinding<T>> {
  using type = T;
};
template <typename T>
struct BindingValue<OptionalBinding<T>> {
  using type = T;
};

/// Which proto message holds the field.
enum class ProtoMessage {
  kNone,                // not in the API
  kRegistrationConfig,  // boicp.v1.RegistrationConfig
  kMapSettings,         // boicp.v1.MapSettings
};

/// The values a request to the daemon may give a number setting (each
/// component of three-number settings), so that no batch makes it allocate
/// or compute without limit. Only given values are checked ("0 = from the
/// scans" stays allowed). The commands that run on the user's own machine
/// do not apply them; whether a value makes sense at all (a positive voxel)
/// is ValidateConfig's and ValidateOccupancySettings' to say.
struct RequestLimits {
  double lower = -std::numeric_limits<double>::infinity();
  double upper = std::numeric_limits<double>::infinity();
};

struct SettingField {
  const char* name;      // identifier; for the registration fields the name
                         // BoIcpConfig::MarkSet and "auto" use
  const char* flag;      // e.g. "--voxel"
  const char* map_flag;  // the flag of map and submit when it differs from `flag`, else nullptr
  const char* json_key;  // key in run.json
  ProtoMessage message;
  const char* proto_field;  // dotted path inside `message`, e.g. "sensor_model.prob_hit"
  unsigned frontends;       // Frontend bits
  const char* help;
  /// Why the setting is missing from a front end of the API (map, submit,
  /// register, the proto); nullptr when it is in all of them.
  const char* absent_because;
  SettingBinding binding;
  RequestLimits limits;  // RequestLimits{} (unbounded) where no value costs the daemon much
};

/// Every setting, registration fields first, in the order help lists them.
const std::vector<SettingField>& SettingSchema();

/// The field named `name`, or nullptr.
const SettingField* FindSetting(const std::string& name);

/// The flag `field` has in `frontend` (map_flag for map and submit when set).
const char* FlagFor(const SettingField& field, Frontend frontend);

}  // namespace boicp::settings
