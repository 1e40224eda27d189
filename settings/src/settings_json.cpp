#include "boicp/settings/settings_json.hpp"

#include <type_traits>

#include "boicp/settings/setting_schema.hpp"
#include "boicp/settings/triple_text.hpp"
#include "boicp/util/types.hpp"

namespace boicp::settings {
namespace {

using nlohmann::json;

// The two shapes settings take in JSON.
enum class Shape {
  kGiven,  // run.json: run.json keys, null when unset, bounds as typed ("a,b,c")
  kUsed,   // a config as used: setting names, bounds as three numbers
};

const char* KeyOf(const SettingField& field, Shape shape) {
  return shape == Shape::kUsed ? field.name : field.json_key;
}

template <typename T>
json OptionalToJson(const std::optional<T>& value) {
  return value ? json(*value) : json(nullptr);
}

json TripleToJson(const std::optional<Eigen::Vector3d>& value, Shape shape) {
  if (shape == Shape::kGiven) return value ? FormatTriple(*value) : std::string();
  return value ? json{(*value)[0], (*value)[1], (*value)[2]} : json(nullptr);
}

// Bounds are "a,b,c" text (as typed, "pi" allowed) or three numbers.
Eigen::Vector3d TripleFromJson(const json& value, const std::string& key) {
  if (value.is_array()) {
    const std::vector<double> numbers = value.get<std::vector<double>>();
    if (numbers.size() != 3) throw InputError(key + ": expected three numbers");
    return Eigen::Vector3d(numbers[0], numbers[1], numbers[2]);
  }
  return ParseTriple(value.get<std::string>(), key);
}

json FieldsToJson(const RequestedSettings& settings, unsigned frontends, Shape shape) {
  json out = json::object();
  for (const SettingField& field : SettingSchema()) {
    if ((field.frontends & frontends) == 0) continue;
    std::visit(
        [&](const auto& binding) {
          using Binding = std::decay_t<decltype(binding)>;
          const auto& value = settings.*binding.requested;
          json& slot = out[KeyOf(field, shape)];
          if constexpr (std::is_same_v<Binding, OptionalBinding<Eigen::Vector3d>>) {
            slot = TripleToJson(value, shape);
          } else if constexpr (kIsPlainBinding<Binding>) {
            slot = value;
          } else {
            slot = OptionalToJson(value);
          }
        },
        field.binding);
  }
  return out;
}

void FieldsFromJson(const json& in, unsigned frontends, Shape shape, const std::string& source,
                    RequestedSettings& settings) {
  for (const SettingField& field : SettingSchema()) {
    if ((field.frontends & frontends) == 0) continue;
    const std::string key = KeyOf(field, shape);
    if (!in.contains(key) || in.at(key).is_null()) continue;
    const json& value = in.at(key);
    try {
      std::visit(
          [&](const auto& binding) {
            using Binding = std::decay_t<decltype(binding)>;
            auto& target = settings.*binding.requested;
            if constexpr (std::is_same_v<Binding, OptionalBinding<Eigen::Vector3d>>) {
              if (!(value.is_string() && value.get<std::string>().empty())) {
                target = TripleFromJson(value, key);
              }
            } else {
              target = value.get<typename BindingValue<Binding>::type>();
            }
          },
          field.binding);
    } catch (const json::exception& e) {
      throw InputError(source + ": bad settings (" + key + ": " + e.what() + ")");
    } catch (const InputError& e) {
      throw InputError(source + ": bad settings (" + e.what() + ")");
    }
  }
}

}  // namespace

json SettingsToJson(const RequestedSettings& settings, unsigned frontends) {
  return FieldsToJson(settings, frontends, Shape::kGiven);
}

void SettingsFromJson(const json& in, unsigned frontends, const std::string& source,
                      RequestedSettings& settings) {
  FieldsFromJson(in, frontends, Shape::kGiven, source, settings);
}

json UsedSettingsToJson(const RequestedSettings& used) {
  // kRegister takes exactly the registration settings.
  json out = FieldsToJson(used, kRegister, Shape::kUsed);
  out.erase("fixed_settings");
  return out;
}

json ConfigToJson(const BoIcpConfig& config) {
  return UsedSettingsToJson(SettingsFromConfig(config));
}

BoIcpConfig ConfigFromJson(const json& in, const std::string& source) {
  RequestedSettings settings;
  FieldsFromJson(in, kRegister, Shape::kUsed, source, settings);
  try {
    return ConfigFromSettings(settings);
  } catch (const InputError& e) {
    throw InputError(source + ": bad settings (" + e.what() + ")");
  }
}

}  // namespace boicp::settings
