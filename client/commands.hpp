#pragma once
// Subcommands of the boicp client. Each Add*Command registers its flags on the
// app and returns the callback that runs it; callbacks return the exit code.

#include <functional>

#include <CLI/CLI.hpp>

namespace boicp::cli {

/// Exit codes that scripts can rely on.
enum ExitCode { kOk = 0, kFailure = 1, kBadInput = 2 };

using CommandRunner = std::function<int()>;

CommandRunner AddRegisterCommand(CLI::App& app);
CommandRunner AddDemoDataCommand(CLI::App& app);

}  // namespace boicp::cli
