#pragma once
// The settings as JSON, from the schema: as given (run.json's settings keys)
// and as used (the `config` object of `register --json`, the pair files and
// run.json's `chosen`).

#include <string>

#include <nlohmann/json.hpp>

#include "boicp/registration/config.hpp"
#include "boicp/settings/requested_settings.hpp"

namespace boicp::settings {

/// Every setting of `frontends` (Frontend bits) under its run.json key:
/// given values, null for an unset number, "" for unset bounds ("a,b,c"
/// otherwise).
nlohmann::json SettingsToJson(const RequestedSettings& settings, unsigned frontends);

/// Reads what SettingsToJson wrote into `settings`; a missing or null key
/// (or "" bounds) leaves the field as it is. Throws InputError naming
/// `source` and the key when a value has the wrong type.
void SettingsFromJson(const nlohmann::json& json, unsigned frontends, const std::string& source,
                      RequestedSettings& settings);

/// The registration settings as used (SettingsFromConfig's, or those a
/// daemon reports for a job), keyed by the setting's name (the names "auto"
/// lists), bounds as three numbers, null where `used` holds no value.
/// fixed_settings is left out: it says how values were chosen, it is not
/// one of them.
nlohmann::json UsedSettingsToJson(const RequestedSettings& used);

/// UsedSettingsToJson of `config`: every registration setting, the "0 =
/// auto" values resolved (EffectiveRefineVoxel, ...).
nlohmann::json ConfigToJson(const BoIcpConfig& config);

/// The config ConfigToJson wrote: its preset with every value read applied
/// and marked set; keys that are not setting names are ignored. Throws
/// InputError naming `source` and the key (a wrong type, an invalid value).
BoIcpConfig ConfigFromJson(const nlohmann::json& json, const std::string& source);

}  // namespace boicp::settings
