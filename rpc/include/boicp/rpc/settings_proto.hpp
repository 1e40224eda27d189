#pragma once
// The registration and map settings as boicp.v1 messages, both ways, from
// the schema's proto field names (boicp/settings/setting_schema.hpp).

#include <string>

#include "boicp/settings/requested_settings.hpp"
#include "boicp/settings/setting_schema.hpp"
#include "boicp/v1/map_builder.pb.h"

namespace boicp::rpc {

namespace v1 = ::boicp::v1;

/// The field's path in a SubmitBatchRequest, as error messages name it:
/// "config.random_samples", "map.sensor_model.prob_hit". Precondition: the
/// API takes the field (message is not kNone).
std::string ProtoFieldPath(const settings::SettingField& field);

/// The given registration settings; unset ones stay unset, so the daemon
/// applies the same preset defaults. Throws InputError for a value the
/// message cannot carry (evaluation_points over 2^32 - 1).
v1::RegistrationConfig RegistrationConfigToProto(const settings::RequestedSettings& settings);

/// The given map settings; unset ones stay unset (chosen from the scans).
v1::MapSettings MapSettingsToProto(const settings::RequestedSettings& settings);

/// What a request gives: a field is given when it is set (fields with
/// presence) or non-zero / non-empty (the others). Throws InputError
/// naming the field ("config.rotation_bounds", "map.cloud_voxel") for
/// non-finite numbers and negative half-widths.
settings::RequestedSettings SettingsFromProto(const v1::RegistrationConfig& config,
                                              const v1::MapSettings& map);

}  // namespace boicp::rpc
