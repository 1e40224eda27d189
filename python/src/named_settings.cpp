#include "named_settings.hpp"

#include "boicp/settings/settings_json.hpp"

namespace boicp::python {
namespace {

using nlohmann::json;

// The names a call takes, for its error message: the schema's settings of
// `frontend`, then `extra_names`.
std::string NamesTaken(settings::Frontend frontend, const json& extra_names) {
  std::string names;
  for (const settings::SettingField& field : settings::SettingSchema()) {
    if (field.frontends & frontend) names += std::string(names.empty() ? "" : ", ") + field.name;
  }
  for (const auto& entry : extra_names.items()) names += ", " + entry.key();
  return names;
}

// `by_name` keyed as run.json keys them: a schema setting by its json_key,
// one of `extra_names`' keys as it is.
json KeyedForJson(const json& by_name, settings::Frontend frontend, const json& extra_names,
                  const std::string& what) {
  if (!by_name.is_object()) throw InputError(what + ": settings must be keyword arguments");
  json keyed = json::object();
  for (const auto& [given, value] : by_name.items()) {
    // `config` is what the command line calls the preset.
    const std::string name = given == "config" ? "preset" : given;
    const settings::SettingField* field = settings::FindSetting(name);
    if (field && (field->frontends & frontend)) {
      keyed[field->json_key] = value;
    } else if (!field && extra_names.contains(name)) {
      keyed[name] = value;
    } else {
      throw InputError(what + ": " + (field ? "this call does not take" : "unknown setting") +
                       " '" + name + "'; it takes " + NamesTaken(frontend, extra_names));
    }
  }
  return keyed;
}

}  // namespace

settings::RequestedSettings RegisterSettingsByName(const json& by_name, const std::string& what) {
  settings::RequestedSettings out;
  settings::SettingsFromJson(KeyedForJson(by_name, settings::kRegister, json::object(), what),
                             settings::kRegister, what, out);
  return out;
}

cli::MapSettings MapSettingsByName(const std::string& folder, const json& by_name,
                                   settings::Frontend frontend, const std::string& what) {
  json manifest = cli::MapSettingsToJson(cli::MapSettings{});
  // run.json's own keys, besides the schema's: the folder and the pairing.
  json extra_names = manifest;
  for (const settings::SettingField& field : settings::SettingSchema()) {
    extra_names.erase(field.json_key);
  }
  extra_names.erase("path");
  manifest.update(KeyedForJson(by_name, frontend, extra_names, what));
  manifest["path"] = folder;
  return cli::WithAbsolutePaths(cli::MapSettingsFromJson(manifest, what));
}

}  // namespace boicp::python
