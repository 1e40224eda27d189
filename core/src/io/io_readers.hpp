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
#include "boicp/io/scan_folder.hpp"

namespace boicp::io_detail {

/// Throws InputError ("no such file", "is a directory", or the OS reason)
/// unless `path` can be opened for reading.
void RequireReadableFile(const std::string& path);

/// The size of `path` in bytes, or InputError naming it and the reason.
uint64_t FileSizeOrThrow(const std::string& path);

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

/// What a checked PCD header declares, as far as Open3D's allocations go.
struct PcdLayout {
  uint64_t points = 0;
  uint64_t point_bytes = 0;       // the sum of the fields' SIZE x COUNT
  uint64_t compressed_bytes = 0;  // binary_compressed only
  bool ascii = false;
  bool compressed = false;  // binary_compressed
  bool normals = false;     // Open3D fills normals as well as points
  bool colors = false;      // and colours
};

/// Throws InputError unless `path` has a PCD v0.7 header whose declared
/// sizes fit the file and whose x/y/z Open3D decodes (see io_pcd_header.cpp),
/// and PointLimitError when it declares more than `max_points` points. Reads
/// the header and the compressed sizes only, not the points.
PcdLayout ReadPcdLayout(const std::string& path, uint64_t max_points);

/// ReadPcdLayout's checks, and for ascii data, that every point has its line.
void RequireSafePcdHeader(const std::string& path, uint64_t max_points);

/// What a checked PLY header declares, as far as Open3D's allocations go.
struct PlyLayout {
  uint64_t vertices = 0;
  bool normals = false;  // Open3D sizes normals as well as points to the vertex count
  bool colors = false;   // and colours
};

/// Throws InputError unless `path` has a PLY header RPly and Open3D read
/// safely, whose vertices fit in the bytes after it (see io_pcd_ply.cpp), and
/// PointLimitError over `max_points` vertices.
PlyLayout RequirePlyHeaderFits(const std::string& path, uint64_t max_points);

/// A PNG's IHDR, when the file starts with one.
struct PngLayout {
  uint64_t width = 0, height = 0;
  uint64_t channels = 1, bit_depth = 8;
};

/// Throws InputError when a PNG header declares more pixels than the file's
/// bytes can hold or than 64 megapixels, PointLimitError over `max_points`
/// pixels; nullopt for a file that is not a PNG (Open3D then refuses it).
std::optional<PngLayout> RequirePlausiblePngSize(const std::string& path, uint64_t max_points);

/// Lines of a text file that hold data (neither blank nor '#' comments).
uint64_t CountDataLines(const std::string& path);

// Each reader refuses more than `max_points` points before allocating them.
Points ReadKittiBin(const std::string& path, uint64_t max_points);
/// PCD or PLY through Open3D; `format` must be kPcd or kPly.
Points ReadPcdOrPly(const std::string& path, CloudFormat format, uint64_t max_points);
Points ReadXyzText(const std::string& path, uint64_t max_points);
Points ReadDepthPng(const std::string& path, const DepthOptions& options, uint64_t max_points);

/// Every scan of a folder or bag, before first, stride and count select some.
struct FullListing {
  std::vector<ScanSource> scans;
  std::vector<std::optional<Transform>> reference_poses;  // empty or one per scan
  std::string what;                                       // e.g. "velodyne/*.bin"
};

/// The scans of a bag (IsBagPath) that `selection` picks, with its odometry
/// as reference poses. Reads every kept message's header stamp.
FullListing ListBagScans(const std::string& path, const BagScanSelection& selection);

/// The PointCloud2 at options.bag_message in the bag file `path`.
Points ReadRosMessage(const std::string& path, const LoadOptions& options);

/// What ReadRosMessage allocates at most: the message, the chunk it is
/// read from (at most as large again) and its points.
uint64_t RosMessageBound(const std::string& path, const LoadOptions& options);

}  // namespace boicp::io_detail
