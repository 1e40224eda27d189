#pragma once
// Internal to boicp_core: the per-format readers behind LoadPointCloud and the
// file / number helpers they share. Readers return every point they decode,
// finite or not, so that LoadPointCloud alone filters and counts non-finite
// points the same way for every format.

#include <fstream>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "boicp/io/point_cloud_io.hpp"

namespace boicp::io_detail {

/// Throws InputError ("no such file", "is a directory", or the OS reason)
/// unless `path` can be opened for reading.
void RequireReadableFile(const std::string& path);

/// Opens `path` or throws InputError naming it and the OS reason.
std::ifstream OpenOrThrow(const std::string& path, std::ios::openmode mode = std::ios::in);

/// What separates the fields of a text line: runs of spaces, tabs, commas or
/// carriage returns (files written on Windows keep their '\r'). Tested a
/// character at a time: a search of a separator string per character costs
/// more than the number parsing of a large file.
inline bool IsFieldSeparator(char c) { return c == ' ' || c == '\t' || c == ',' || c == '\r'; }

/// Splits a text line into its fields (IsFieldSeparator).
std::vector<std::string_view> SplitFields(std::string_view line);

/// Parses a whole token as a double, independent of the C locale. Accepts a
/// leading '+', "nan" and "inf"; returns nullopt for anything else.
std::optional<double> ParseNumber(std::string_view token);

/// True for lines that hold no data: empty, blank, or a '#' comment.
bool IsBlankOrComment(std::string_view line);

/// Every number of a small text file, skipping blank and '#' lines. Throws
/// InputError "path:LINE: 'token' is not a number".
std::vector<double> ReadNumbersFile(const std::string& path);

/// Throws PointLimitError when `points` is over `max_points`.
void RequirePointCount(const std::string& path, uint64_t points, uint64_t max_points);

/// Throws InputError unless `path` has a PCD v0.7 header whose declared
/// sizes fit the file and whose x/y/z Open3D decodes (see io_pcd_header.cpp),
/// and PointLimitError when it declares more than `max_points` points.
void RequireSafePcdHeader(const std::string& path, uint64_t max_points);

// Each reader refuses more than `max_points` points before allocating them.
Points ReadKittiBin(const std::string& path, uint64_t max_points);
/// PCD or PLY through Open3D; `format` must be kPcd or kPly.
Points ReadPcdOrPly(const std::string& path, CloudFormat format, uint64_t max_points);
Points ReadXyzText(const std::string& path, uint64_t max_points);
Points ReadDepthPng(const std::string& path, const DepthOptions& options, uint64_t max_points);

}  // namespace boicp::io_detail
