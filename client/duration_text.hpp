#pragma once
// Durations as progress lines, watch lines and job summaries print them.

#include <string>

namespace boicp::cli {

/// "1h02m", "3m05s", "42s"; "?" when negative or not a number.
std::string FormatDuration(double seconds);

}  // namespace boicp::cli
