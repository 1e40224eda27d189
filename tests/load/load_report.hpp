#pragma once
// A load run's figures as text, and the checks that decide whether it passed.

#include <ostream>
#include <string>
#include <vector>

#include "load_run.hpp"

namespace boicp::load {

/// Why the run failed: failed or unfinished jobs, unexpected RPC errors, no
/// completed job at all, RSS growth over the bound, a daemon that did not
/// stop cleanly, or harness errors. Empty = passed.
std::vector<std::string> CheckFigures(const LoadFigures& figures, const LoadOptions& options);

/// Writes the settings, the figures, a line per RPC and the verdict.
void WriteFigures(std::ostream& out, const LoadFigures& figures, const LoadOptions& options,
                  const std::vector<std::string>& problems);

}  // namespace boicp::load
