#include "boicp/settings/settings_flags.hpp"

#include <type_traits>

#include "boicp/settings/triple_text.hpp"
#include "boicp/util/types.hpp"

namespace boicp::settings {
namespace {

// A word the engine does not know (--config, --mode, --budget, ...) is the
// flag's error. Each word is tried alone on the defaults, so that the one
// message names the flag as the user typed it and the words it allows.
void CheckWords(const RequestedSettings& settings, Frontend frontend) {
  for (const SettingField& field : SettingSchema()) {
    const auto* binding = std::get_if<PlainBinding<std::string>>(&field.binding);
    if (binding == nullptr || (field.frontends & frontend) == 0) continue;
    RequestedSettings alone;
    alone.*binding->requested = settings.*binding->requested;
    try {
      ConfigFromSettings(alone);
      MapBuildFromSettings(alone);
    } catch (const InputError& e) {
      throw InputError(std::string(FlagFor(field, frontend)) + ": " + e.what());
    }
  }
}

}  // namespace

void AddSettingFlags(CLI::App& app, Frontend frontend, RequestedSettings& settings,
                     FlagTexts& texts) {
  for (const SettingField& field : SettingSchema()) {
    if ((field.frontends & frontend) == 0) continue;
    const std::string flag = FlagFor(field, frontend);
    std::visit(
        [&](const auto& binding) {
          using Binding = std::decay_t<decltype(binding)>;
          auto& value = settings.*binding.requested;
          if constexpr (std::is_same_v<Binding, PlainBinding<bool>>) {
            app.add_flag(flag, value, field.help);
          } else if constexpr (std::is_same_v<Binding, OptionalBinding<Eigen::Vector3d>>) {
            const std::string name = field.name;
            app.add_option_function<std::string>(
                flag, [&texts, name](const std::string& text) { texts[name] = text; }, field.help);
          } else if constexpr (std::is_same_v<Binding, PlainBinding<std::string>> ||
                               std::is_same_v<Binding, PlainBinding<uint64_t>>) {
            app.add_option(flag, value, field.help)->capture_default_str();
          } else {
            app.add_option(flag, value, field.help);
          }
        },
        field.binding);
  }
}

void ApplyFlagTexts(const FlagTexts& texts, Frontend frontend, RequestedSettings& settings) {
  for (const auto& [name, text] : texts) {
    const SettingField* field = FindSetting(name);
    const auto* binding =
        field ? std::get_if<OptionalBinding<Eigen::Vector3d>>(&field->binding) : nullptr;
    if (binding == nullptr) throw std::logic_error("no three-number setting '" + name + "'");
    settings.*binding->requested = ParseTriple(text, FlagFor(*field, frontend));
  }
  CheckWords(settings, frontend);
}

}  // namespace boicp::settings
