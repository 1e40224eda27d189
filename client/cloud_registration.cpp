#include "cloud_registration.hpp"

#include "json_output.hpp"

namespace boicp::cli {

PairSettingsChoice ChooseCloudPairSettings(PointSpan source, PointSpan target, BoIcpConfig config,
                                           CloudFormat source_format) {
  PairSettingsChoice out;
  out.chosen =
      ChooseSettingsForClouds({source, target}, DeclareSensor(config.sensor, source_format),
                              config.seed, 2, config.threads);
  out.auto_fields = ApplyChosenSettings(out.chosen, config);
  ValidateConfig(config);
  out.config = std::move(config);
  return out;
}

RegistrationResult RegisterCloudPair(PointSpan source, PointSpan target,
                                     const PairSettingsChoice& settings,
                                     const std::optional<Transform>& prior,
                                     const RegistrationCallbacks& callbacks) {
  PairHints hints;
  hints.prior = prior;
  return CoreMethods()
      .Create(settings.config.method, settings.config)
      ->RegisterClouds(source, target, hints, callbacks);
}

nlohmann::json RegisterReportJson(const RegistrationResult& result,
                                  const PairSettingsChoice& settings) {
  nlohmann::json out = RegistrationToJson(result, settings.auto_fields);
  out["far_returns"] = {{"source", settings.chosen.far_returns[0]},
                        {"target", settings.chosen.far_returns[1]}};
  out["sensor"] = {{"type", SensorKindName(settings.chosen.sensor)},
                   {"why", settings.chosen.sensor_reason}};
  return out;
}

}  // namespace boicp::cli
