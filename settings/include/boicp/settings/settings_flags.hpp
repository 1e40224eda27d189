#pragma once
// The command-line flags of the settings a front end takes, from the schema.

#include <map>
#include <string>

#include <CLI/CLI.hpp>

#include "boicp/settings/requested_settings.hpp"
#include "boicp/settings/setting_schema.hpp"

namespace boicp::settings {

/// Flag values read only when the command runs (three-number values), by
/// field name, so that a malformed one is the command's input error.
using FlagTexts = std::map<std::string, std::string>;

/// Registers on `app` the flag of every setting `frontend` takes: given
/// values land in `settings` (or, for three-number values, in `texts`).
/// Both must outlive the parse.
void AddSettingFlags(CLI::App& app, Frontend frontend, RequestedSettings& settings,
                     FlagTexts& texts);

/// Parses `texts` into `settings` and checks the word settings (--config,
/// --mode, --budget, ...). Throws InputError naming the flag.
void ApplyFlagTexts(const FlagTexts& texts, Frontend frontend, RequestedSettings& settings);

}  // namespace boicp::settings
