#pragma once
// Client text (labels, ids) in log lines: one log line must stay one line,
// so control bytes and backslashes are written as escapes.

#include <string>

namespace boicp::server {

/// `text` with '\\', '\n', '\r', '\t' and every other byte under 0x20 or 0x7f
/// escaped (\\n, \\x1b, ...); everything else as it is.
std::string EscapeForLog(const std::string& text);

}  // namespace boicp::server
