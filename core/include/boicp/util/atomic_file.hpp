#pragma once
// Writing output files so that a reader (a restarted daemon, a rerun after a
// kill, another shard) sees either the old file or the whole new one, never
// a torn one.

#include <functional>
#include <string>

namespace boicp {

/// Calls write(staging_path), flushes the staging file to disk and renames it
/// over `path`. The staging file sits beside `path` and is named after this
/// process and thread ("<path>.<pid>-<thread>.tmp"), so several writers of one
/// path (shards) never share it: the last rename wins. On failure the staging
/// file is removed and std::runtime_error names the file (exceptions thrown
/// by `write` pass through).
void WriteFileAtomically(const std::string& path,
                         const std::function<void(const std::string& staging_path)>& write);

/// WriteFileAtomically with `content` as the file's bytes.
void WriteTextFileAtomically(const std::string& path, const std::string& content);

}  // namespace boicp
