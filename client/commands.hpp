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
CommandRunner AddMapCommand(CLI::App& app);
CommandRunner AddPreviewCommand(CLI::App& app);
CommandRunner AddMergeCommand(CLI::App& app);
CommandRunner AddInfoCommand(CLI::App& app);
CommandRunner AddEvalCommand(CLI::App& app);

#ifdef BOICP_WITH_REMOTE_COMMANDS
// Talking to the daemon boicpd (built with it).
CommandRunner AddSubmitCommand(CLI::App& app);
CommandRunner AddWatchCommand(CLI::App& app);
CommandRunner AddJobsCommand(CLI::App& app);
CommandRunner AddShowCommand(CLI::App& app);
CommandRunner AddCancelCommand(CLI::App& app);
CommandRunner AddDeleteCommand(CLI::App& app);
CommandRunner AddExportCommand(CLI::App& app);
CommandRunner AddHealthCommand(CLI::App& app);
#endif

}  // namespace boicp::cli
