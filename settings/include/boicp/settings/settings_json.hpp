#pragma once
// The settings as run.json stores them, from the schema.

#include <string>

#include <nlohmann/json.hpp>

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

}  // namespace boicp::settings
