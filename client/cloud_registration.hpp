#pragma once
// One pair of clouds registered as `boicp register` does it: the settings
// left automatic chosen from the two clouds, the method run, and the result
// as `register --json` prints it. The Python module runs the same functions.

#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "boicp/io/point_cloud_io.hpp"
#include "boicp/registration/auto_settings.hpp"
#include "boicp/registration/registration_method.hpp"

namespace boicp::cli {

/// The settings of one pair, final.
struct PairSettingsChoice {
  BoIcpConfig config;                    // nothing automatic left, validated
  std::vector<std::string> auto_fields;  // the fields chosen from the clouds
  ChosenSettings chosen;                 // what they were chosen from, and why
};

/// Chooses what `config` leaves automatic from the two clouds (the sensor as
/// config.sensor says, else as `source_format` and the geometry show) and
/// validates the result. Throws InputError for clouds too small to choose
/// from, clouds of different units, or invalid settings.
PairSettingsChoice ChooseCloudPairSettings(PointSpan source, PointSpan target, BoIcpConfig config,
                                           CloudFormat source_format);

/// Registers `source` onto `target` with config.method (T_target_source),
/// from `prior` when given. Throws Cancelled when callbacks.stop_requested
/// fires, InputError for clouds the method cannot use.
RegistrationResult RegisterCloudPair(PointSpan source, PointSpan target,
                                     const PairSettingsChoice& settings,
                                     const std::optional<Transform>& prior,
                                     const RegistrationCallbacks& callbacks = {});

/// `register --json`'s object: RegistrationToJson, plus "far_returns"
/// ({"source", "target"}: points set aside while choosing the settings) and
/// "sensor" ({"type", "why"}).
nlohmann::json RegisterReportJson(const RegistrationResult& result,
                                  const PairSettingsChoice& settings);

}  // namespace boicp::cli
