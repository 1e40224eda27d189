#pragma once
// Three numbers as a flag or run.json writes them: "a,b,c".

#include <string>

#include <Eigen/Core>

namespace boicp::settings {

/// "a,b,c": three finite numbers, each also "pi". Throws InputError naming `flag`.
Eigen::Vector3d ParseTriple(const std::string& text, const std::string& flag);

/// "a,b,c" with the digits ParseTriple needs to read the same numbers back
/// (15 significant digits where they suffice, else 17).
std::string FormatTriple(const Eigen::Vector3d& values);

}  // namespace boicp::settings
