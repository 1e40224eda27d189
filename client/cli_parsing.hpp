#pragma once
// Small parsers for flag values shared by the subcommands.

#include <string>

#include <Eigen/Core>

namespace boicp::cli {

/// "a,b,c": three finite numbers, each also "pi". Throws InputError naming `flag`.
Eigen::Vector3d ParseTriple(const std::string& text, const std::string& flag);

/// True when stderr is a terminal (progress may redraw one line).
bool StderrIsTerminal();

}  // namespace boicp::cli
