#pragma once
// Small text helpers shared by the daemon, the CLI and the bench.

#include <string>

namespace boicp {

/// `text` without leading and trailing spaces, tabs, carriage returns and
/// line feeds (a line read from a token file or /proc).
std::string Trim(const std::string& text);

/// `text` with its letters lowered one byte at a time (std::tolower), for
/// extensions, names and keywords that are matched in any case.
std::string LowerCase(std::string text);

}  // namespace boicp
