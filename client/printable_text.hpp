#pragma once
// Text from the daemon (labels, stages, errors) or from files, made safe to
// print on a terminal.

#include <string>

namespace boicp::cli {

/// `text` on one line with no control characters: line breaks and tabs
/// become spaces, and every other C0 control, DEL and C1 control (as UTF-8)
/// is shown as \xNN, so that printing it cannot move the cursor, clear the
/// screen or retitle the window. Other bytes, UTF-8 included, pass as they are.
std::string PrintableText(const std::string& text);

}  // namespace boicp::cli
