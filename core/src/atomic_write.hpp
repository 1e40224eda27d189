#pragma once
// Internal to boicp_core: writing an output file so that a reader (or a
// restarted daemon) sees either the old file or the whole new one.

#include <functional>
#include <string>

namespace boicp::detail {

/// Calls write(tmp_path) with tmp_path = path + ".tmp", flushes it to disk
/// and renames it over `path`. Throws std::runtime_error naming the file.
void WriteFileAtomically(const std::string& path,
                         const std::function<void(const std::string& tmp_path)>& write);

}  // namespace boicp::detail
