#include "boicp/settings/settings_flags.hpp"

#include <type_traits>

#include "boicp/settings/triple_text.hpp"

namespace boicp::settings {

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
}

}  // namespace boicp::settings
