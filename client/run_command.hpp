#pragma once
// How every subcommand turns an exception into its one error line and exit code.

#include <functional>
#include <string>

namespace boicp::cli {

/// Runs `body` and returns its exit code. An InputError or LimitExceeded
/// (input or settings the command cannot use) is printed as "boicp
/// COMMAND: error: MESSAGE" on stderr and returns kBadInput; any other
/// exception is printed the same way and returns kFailure. Control
/// characters in the message are escaped (PrintableText).
int RunCommand(const std::string& command, const std::function<int()>& body);

/// The error line alone, as RunCommand prints it; returns `code`.
int ReportCommandError(const std::string& command, const std::string& message, int code);

}  // namespace boicp::cli
