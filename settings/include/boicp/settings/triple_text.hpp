#pragma once
// Three numbers as a flag or run.json writes them: "a,b,c".

#include <string>

#include <Eigen/Core>

namespace boicp::settings {

/// "a,b,c": three finite numbers, each also "pi". Throws InputError naming `flag`.
Eigen::Vector3d ParseTriple(const std::string& text, const std::string& flag);

/// "a,b,c" with every digit ParseTriple needs to read the same numbers back.
std::string FormatTriple(const Eigen::Vector3d& values);

}  // namespace boicp::settings
