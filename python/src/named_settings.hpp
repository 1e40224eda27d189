#pragma once
// Settings as Python keywords give them: the schema's setting names
// (setting_schema.hpp), read through the same JSON reader and validation as
// run.json.

#include <string>

#include <nlohmann/json.hpp>

#include "boicp/settings/setting_schema.hpp"
#include "local_pipeline.hpp"

namespace boicp::python {

/// `boicp register`'s settings from `by_name`, a JSON object of setting name
/// -> value (three-number settings as three numbers or "a,b,c" text).
/// Throws InputError naming `what` and an unknown or misplaced name (with
/// the names there are) or a bad value.
settings::RequestedSettings RegisterSettingsByName(const nlohmann::json& by_name,
                                                   const std::string& what);

/// The settings of a `boicp map` (or, with kSubmit, `boicp submit`) run of
/// `folder`: its defaults, then `by_name`'s schema settings and run.json's
/// folder and pairing keys (layout, first, stride, count, pairing,
/// pairs_file, overlap_threshold, extra_pairs_file, intrinsics, camera,
/// depth_scale, poses_as_priors). Paths are made absolute. Throws InputError
/// as RegisterSettingsByName.
cli::MapSettings MapSettingsByName(const std::string& folder, const nlohmann::json& by_name,
                                   settings::Frontend frontend, const std::string& what);

}  // namespace boicp::python
