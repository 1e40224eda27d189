#include "boicp/settings/settings_json.hpp"

#include <type_traits>

#include "boicp/settings/setting_schema.hpp"
#include "boicp/settings/triple_text.hpp"
#include "boicp/util/types.hpp"

namespace boicp::settings {
namespace {

using nlohmann::json;

template <typename T>
json OptionalToJson(const std::optional<T>& value) {
  return value ? json(*value) : json(nullptr);
}

// Bounds are "a,b,c" text (as typed, "pi" allowed); arrays are read too.
Eigen::Vector3d TripleFromJson(const json& value, const std::string& key) {
  if (value.is_array()) {
    const std::vector<double> numbers = value.get<std::vector<double>>();
    if (numbers.size() != 3) throw InputError(key + ": expected three numbers");
    return Eigen::Vector3d(numbers[0], numbers[1], numbers[2]);
  }
  return ParseTriple(value.get<std::string>(), key);
}

}  // namespace

json SettingsToJson(const RequestedSettings& settings, unsigned frontends) {
  json out = json::object();
  for (const SettingField& field : SettingSchema()) {
    if ((field.frontends & frontends) == 0) continue;
    std::visit(
        [&](const auto& binding) {
          using Binding = std::decay_t<decltype(binding)>;
          const auto& value = settings.*binding.requested;
          if constexpr (std::is_same_v<Binding, OptionalBinding<Eigen::Vector3d>>) {
            out[field.json_key] = value ? FormatTriple(*value) : std::string();
          } else if constexpr (kIsPlainBinding<Binding>) {
            out[field.json_key] = value;
          } else {
            out[field.json_key] = OptionalToJson(value);
          }
        },
        field.binding);
  }
  return out;
}

void SettingsFromJson(const json& in, unsigned frontends, const std::string& source,
                      RequestedSettings& settings) {
  for (const SettingField& field : SettingSchema()) {
    if ((field.frontends & frontends) == 0) continue;
    const std::string key = field.json_key;
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
      throw InputError(source + ": bad run settings (" + key + ": " + e.what() + ")");
    } catch (const InputError& e) {
      throw InputError(source + ": bad run settings (" + e.what() + ")");
    }
  }
}

}  // namespace boicp::settings
