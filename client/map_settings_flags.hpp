#pragma once
// The flags `boicp map` and `boicp submit` share: the scan folder and how to
// read it, the BO-ICP preset and its overrides, the pairing and the map
// settings. One registration, so both commands spell and default them alike.

#include <cstdint>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "boicp/settings/settings_flags.hpp"
#include "local_pipeline.hpp"

namespace boicp::cli {

/// What the shared flags parse into. `pairing_words` holds every word CLI11
/// handed to --pairing: MODE, FILE for explicit, and PATH when PATH came last.
struct MapSettingsFlags {
  MapSettings settings;
  settings::FlagTexts setting_texts;
  settings::Frontend frontend = settings::kMap;
  std::vector<std::string> pairing_words = {"consecutive"};
  std::vector<std::string> paths;  // PATH: one, or several drives
};

/// Registers PATH and the shared flags on `app`, with the settings the
/// schema gives `frontend` (kMap or kSubmit).
void AddMapSettingsFlags(CLI::App& app, MapSettingsFlags& flags,
                         settings::Frontend frontend = settings::kMap);

/// Adds --max-fusion-mb for the commands that fuse a map locally, its value
/// defaulting to DefaultFusionLimitMb().
void AddFusionLimitFlag(CLI::App& app, uint64_t& max_fusion_mb);

/// The settings with --pairing's words split into mode, FILE and PATH.
/// Throws InputError for a stray word, a missing PATH or a malformed value.
MapSettings ResolveMapSettings(const MapSettingsFlags& flags);

}  // namespace boicp::cli
