#pragma once
// A value for every setting of the schema, different from every preset's,
// for the round-trip tests.

#include <string>
#include <type_traits>
#include <vector>

#include "boicp/settings/setting_schema.hpp"
#include "boicp/settings/settings_flags.hpp"
#include "boicp/settings/settings_json.hpp"

namespace boicp::settings {

/// A word setting's value, other than its default (--config: the preset).
inline std::string ExampleWord(const std::string& flag) {
  if (flag == "--mode") return "6dof";
  if (flag == "--icp-objective") return "point";
  if (flag == "--budget") return "fixed";
  if (flag == "--sensor") return "depth";
  if (flag == "--method") return "icp";
  if (flag == "--loops") return "off";
  if (flag == "--untrusted-scans") return "place";
  return "B";
}

/// The command line that gives every setting of `frontend` a value:
/// method icp, preset B, mode 6dof, ICP objective point, budget fixed,
/// sensor depth, loops off, untrusted scans placed, switches on,
/// the n-th number field n + 0.25 (the refinement voxel 0.25, counts n + 7),
/// bounds "0.25,0.5,1.25".
inline std::vector<std::string> ExampleArguments(Frontend frontend) {
  std::vector<std::string> args = {"test"};
  int n = 0;
  for (const SettingField& field : SettingSchema()) {
    if ((field.frontends & frontend) == 0) continue;
    ++n;
    const std::string flag = FlagFor(field, frontend);
    std::visit(
        [&](const auto& binding) {
          using Binding = std::decay_t<decltype(binding)>;
          if constexpr (std::is_same_v<Binding, PlainBinding<bool>>) {
            args.push_back(flag);
            return;
          }
          std::string value;
          if constexpr (std::is_same_v<Binding, PlainBinding<std::string>>) {
            value = ExampleWord(flag);
          } else if constexpr (std::is_same_v<Binding, OptionalBinding<double>>) {
            // The refinement voxel may not exceed the search voxel.
            value = flag == "--refine-voxel" ? "0.25" : std::to_string(n) + ".25";
          } else if constexpr (std::is_same_v<Binding, OptionalBinding<Eigen::Vector3d>>) {
            value = "0.25,0.5,1.25";
          } else {
            value = std::to_string(n + 7);
          }
          args.push_back(flag);
          args.push_back(value);
        },
        field.binding);
  }
  return args;
}

/// What `args` (argv[0] first) give through the flags of `frontend`.
inline RequestedSettings ParseFlags(Frontend frontend, const std::vector<std::string>& args) {
  RequestedSettings settings;
  FlagTexts texts;
  CLI::App app;
  AddSettingFlags(app, frontend, settings, texts);
  std::vector<const char*> argv;
  for (const std::string& arg : args) argv.push_back(arg.c_str());
  app.parse(static_cast<int>(argv.size()), argv.data());
  ApplyFlagTexts(texts, frontend, settings);
  return settings;
}

/// Every field under its run.json key, to compare settings with.
inline nlohmann::json AllFields(const RequestedSettings& settings) {
  return SettingsToJson(settings, kRegister | kMap | kSubmit | kBench);
}

}  // namespace boicp::settings
