#pragma once
// Small parsers for flag values shared by the subcommands.

#include <string>

#include <Eigen/Core>

namespace boicp::cli {

/// Parses "a,b,c" into three finite numbers; throws boicp::InputError naming `flag`.
Eigen::Vector3d ParseTriple(const std::string& text, const std::string& flag);

/// True when stderr is a terminal (progress may redraw one line).
bool StderrIsTerminal();

}  // namespace boicp::cli
