#pragma once
// Small parsers for flag values shared by the subcommands.

#include <optional>
#include <string>

#include <Eigen/Core>

#include "boicp/settings/triple_text.hpp"

namespace boicp::cli {

using settings::ParseTriple;

/// The --sensor-up value: a non-zero "x,y,z" direction in the scan frame,
/// or nullopt for an empty text. Throws boicp::InputError otherwise.
std::optional<Eigen::Vector3d> ParseSensorUp(const std::string& text);

/// The --sensor-up help text, shared by the commands that render previews.
extern const char* const kSensorUpHelp;

/// True when stderr is a terminal (progress may redraw one line).
bool StderrIsTerminal();

}  // namespace boicp::cli
