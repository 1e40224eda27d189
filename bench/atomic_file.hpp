#pragma once
// Output files that never appear half written.

#include <string>

namespace boicp::bench {

/// Writes `text` to a temporary file beside `path`, then renames it over
/// `path`, so a reader (or a run killed mid-write) sees the old file or the
/// new one, never a mix. Throws InputError when the folder is not writable.
void WriteFileAtomically(const std::string& path, const std::string& text);

}  // namespace boicp::bench
