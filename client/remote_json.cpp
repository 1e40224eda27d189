#include "remote_json.hpp"

#include <cstdio>
#include <stdexcept>
#include <string>

#include <google/protobuf/util/json_util.h>

#include "boicp/rpc/pair_result_proto.hpp"
#include "boicp/rpc/settings_proto.hpp"
#include "boicp/settings/pair_result_json.hpp"
#include "boicp/settings/settings_json.hpp"
#include "json_output.hpp"

namespace boicp::cli {

nlohmann::json ChosenSettingsToJson(const v1::ChosenSettings& s) {
  nlohmann::json out =
      settings::UsedSettingsToJson(rpc::SettingsFromProto(s.config(), v1::MapSettings()));
  // Settings the API does not carry have no value here: left out.
  for (auto it = out.begin(); it != out.end();) it = it->is_null() ? out.erase(it) : ++it;
  out["map_resolution"] = s.map_resolution();
  out["map_max_range"] = s.map_max_range();
  out["auto"] = s.auto_fields();
  out["far_returns"] = s.far_returns();
  if (!s.sensor().empty()) out["sensor"] = {{"type", s.sensor()}, {"why", s.sensor_why()}};
  return out;
}

std::string DescribeChosenSettings(const v1::ChosenSettings& s) {
  const v1::RegistrationConfig& c = s.config();
  std::string automatic;
  for (const std::string& field : s.auto_fields()) {
    automatic += (automatic.empty() ? "" : ", ") + field;
  }
  // Jobs stored before the budget existed carry none.
  const std::string budget = c.budget().empty() ? "" : ", budget " + c.budget();
  const std::string far_returns =
      s.far_returns() == 0
          ? ""
          : "; " + std::to_string(s.far_returns()) + " far returns set aside while choosing";
  const std::string sensor =
      s.sensor().empty() ? "" : "; sensor " + s.sensor() + " (" + s.sensor_why() + ")";
  char text[512];
  std::snprintf(text, sizeof text,
                "preset %s, %s%s, voxel %.3g m, refine voxel %.3g m, translation bounds "
                "%.3g,%.3g,%.3g m, rotation bounds %.3g,%.3g,%.3g rad, map resolution %.3g m, "
                "ray length %.3g m%s%s",
                c.preset().c_str(), c.mode().c_str(), budget.c_str(), c.voxel(), c.refine_voxel(),
                c.translation_bounds().x(), c.translation_bounds().y(), c.translation_bounds().z(),
                c.rotation_bounds().x(), c.rotation_bounds().y(), c.rotation_bounds().z(),
                s.map_resolution(), s.map_max_range(),
                automatic.empty() ? "" : "; from the scans: ", automatic.c_str());
  return text + far_returns + sensor;
}

nlohmann::json JobToJson(const v1::Job& job) {
  // Every field under its .proto name, defaults included, so that a field
  // the daemon gains reaches scripts without a change here; the state by its
  // short name, and the settings as `register --json` prints them.
  google::protobuf::util::JsonPrintOptions options;
  options.preserve_proto_field_names = true;
  options.always_print_primitive_fields = true;
  std::string text;
  const auto status = google::protobuf::util::MessageToJsonString(job, &text, options);
  if (!status.ok()) throw std::runtime_error("job " + job.job_id() + ": " + status.ToString());
  nlohmann::json out = nlohmann::json::parse(text);
  out["state"] = rpc::JobStateName(job.state());
  out.erase("stage_code");  // "stage" names it
  out["settings"] = job.has_settings() ? ChosenSettingsToJson(job.settings()) : nlohmann::json();
  return out;
}

nlohmann::json PairToJson(const v1::PairResult& pair) {
  nlohmann::json out = settings::PairResultToJson(rpc::PairResultFromProto(pair), kPairApi);
  out["source_scan_id"] = pair.source_scan_id();
  out["target_scan_id"] = pair.target_scan_id();
  return out;
}

nlohmann::json ResultsToJson(const v1::JobResults& results) {
  nlohmann::json json = JobToJson(results.job());
  json["pairs"] = nlohmann::json::array();
  for (const v1::PairResult& pair : results.pairs()) json["pairs"].push_back(PairToJson(pair));
  json["trajectory"] = nlohmann::json::array();
  for (const v1::TrajectoryPose& pose : results.trajectory()) {
    json["trajectory"].push_back(
        {{"index", pose.index()},
         {"scan_id", pose.scan_id()},
         {"timestamp", pose.timestamp()},
         {"pose", TransformToJson(rpc::TransformFromProto(pose.pose(), "trajectory.pose"))}});
  }
  return json;
}

}  // namespace boicp::cli
