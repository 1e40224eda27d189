#include "boicp/settings/requested_settings.hpp"

#include <cmath>
#include <type_traits>

#include "boicp/registration/registration_method.hpp"
#include "boicp/settings/setting_schema.hpp"
#include "boicp/util/types.hpp"

namespace boicp::settings {
namespace {

// Calls `action` with the field's binding when it is an OptionalBinding.
template <typename Action>
void VisitOptional(const SettingField& field, Action&& action) {
  std::visit(
      [&](const auto& binding) {
        if constexpr (!kIsPlainBinding<std::decay_t<decltype(binding)>>) action(binding);
      },
      field.binding);
}

}  // namespace

BoIcpConfig ConfigFromSettings(const RequestedSettings& settings) {
  BoIcpConfig config = PresetConfig(settings.preset);
  CoreMethods().Require(settings.method);
  config.method = settings.method;
  if (settings.fixed_settings) config.automatic.clear();
  config.mode = ParseSearchMode(settings.mode);
  config.icp_objective = ParseIcpObjective(settings.icp_objective);
  config.budget = ParseBudget(settings.budget);
  config.sensor = ParseSensorSetting(settings.sensor);
  config.retry_when_doubtful = !settings.no_retry;
  config.seed = settings.seed;
  for (const SettingField& field : SettingSchema()) {
    VisitOptional(field, [&](const auto& binding) {
      const auto& value = settings.*binding.requested;
      if (binding.config != nullptr && value) {
        config.*binding.config = *value;
        config.MarkSet(field.name);
      }
    });
  }
  if (settings.rotation_bounds) {
    config.rotation_bounds = SnapRotationBounds(config.rotation_bounds);
  }
  ValidateConfig(config);
  return config;
}

RequestedSettings SettingsFromConfig(const BoIcpConfig& config) {
  RequestedSettings settings;
  settings.method = config.method;
  settings.preset = config.preset;
  settings.mode = SearchModeName(config.mode);
  settings.icp_objective = IcpObjectiveName(config.icp_objective);
  settings.budget = BudgetName(config.budget);
  settings.sensor = SensorSettingName(config.sensor);
  settings.seed = config.seed;
  settings.no_retry = !config.retry_when_doubtful;
  for (const SettingField& field : SettingSchema()) {
    VisitOptional(field, [&](const auto& binding) {
      if (binding.config == nullptr) return;
      settings.*binding.requested =
          binding.effective != nullptr ? (config.*binding.effective)() : config.*binding.config;
    });
  }
  return settings;
}

MapBuildSettings MapBuildFromSettings(const RequestedSettings& settings) {
  MapBuildSettings map;
  OccupancySettings& o = map.occupancy;
  o.resolution = settings.resolution.value_or(o.resolution);
  o.max_range = settings.max_range.value_or(o.max_range);
  o.prob_hit = settings.prob_hit.value_or(o.prob_hit);
  o.prob_miss = settings.prob_miss.value_or(o.prob_miss);
  o.clamp_min = settings.clamp_min.value_or(o.clamp_min);
  o.clamp_max = settings.clamp_max.value_or(o.clamp_max);
  ValidateOccupancySettings(o);
  map.cloud_voxel = settings.cloud_voxel.value_or(map.cloud_voxel);
  if (!std::isfinite(map.cloud_voxel) || map.cloud_voxel < 0.0) {
    throw InputError("map settings: cloud_voxel must be >= 0 (0 = resolution)");
  }
  map.loops = LoopSearchFromName(settings.loops, "loops");
  map.untrusted_scans = UntrustedScansFromName(settings.untrusted_scans, "untrusted_scans");
  return map;
}

MapAutoFields MapAutoFromSettings(const RequestedSettings& settings) {
  MapAutoFields map_auto;
  map_auto.resolution = !settings.fixed_settings && !settings.resolution;
  map_auto.max_range = !settings.fixed_settings && !settings.max_range;
  return map_auto;
}

}  // namespace boicp::settings
