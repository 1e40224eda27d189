#pragma once
// Loading point clouds from files: KITTI .bin, PCD, PLY, XYZ text and 16-bit
// depth PNGs. Every loader drops non-finite points and counts them; every
// failure throws boicp::InputError with a one-line message naming the file.

#include <cstddef>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "boicp/io/bag_reader.hpp"
#include "boicp/io/decode_budget.hpp"
#include "boicp/util/types.hpp"

namespace boicp {

/// kRosMessage: a sensor_msgs/PointCloud2 inside a bag (LoadOptions::bag_message).
enum class CloudFormat { kAuto, kKittiBin, kPcd, kPly, kXyz, kDepthPng, kRosMessage };

/// Parses "auto", "kitti"/"bin", "pcd", "ply", "xyz", "depth"/"png".
/// Throws InputError for anything else.
CloudFormat ParseCloudFormat(const std::string& name);
std::string CloudFormatName(CloudFormat format);

/// Format from the file extension (.bin .pcd .ply .xyz .txt .png, any case).
/// Throws InputError when the extension is not one of these.
CloudFormat DetectCloudFormat(const std::string& path);

/// Pinhole intrinsics of a depth camera, in pixels. Pixel centres sit at
/// integer (u = column, v = row) coordinates.
struct Intrinsics {
  double fx = 0.0, fy = 0.0, cx = 0.0, cy = 0.0;
};

/// Parses "fx,fy,cx,cy". Throws InputError unless four finite numbers with fx, fy > 0.
Intrinsics ParseIntrinsics(const std::string& text);

/// Reads intrinsics from a file holding either four numbers "fx fy cx cy" or a
/// 3x3 camera matrix K (as 7-Scenes' camera-intrinsics.txt). Throws InputError.
Intrinsics ReadIntrinsicsFile(const std::string& path);

/// How to turn a depth PNG into points. There are no default intrinsics or
/// scale on purpose: TUM uses 5000 per metre, 7-Scenes 1000.
struct DepthOptions {
  std::optional<Intrinsics> intrinsics;               // required for depth images
  double depth_scale = 0.0;                           // raw units per metre; required (> 0)
  std::vector<uint16_t> invalid_values = {0, 65535};  // raw values that mean "no depth"
};

/// Points a loader accepts unless told otherwise: about 120 MB of points.
constexpr uint64_t kDefaultMaxPoints = 5000000;

struct LoadOptions {
  CloudFormat format = CloudFormat::kAuto;  // kAuto: from the extension
  DepthOptions depth;
  /// kRosMessage: the scan's message in the bag the path names (its storage
  /// file: the .bag, .db3 or .mcap).
  std::optional<BagMessageRef> bag_message;
  /// More points than this (as the header declares them, or as counted for
  /// text) is refused before the points are allocated.
  uint64_t max_points = kDefaultMaxPoints;
  /// The process's decoding memory, shared with other loads; null: none.
  /// When set, LoadPointCloud takes DecodeBoundBytes from it before it
  /// decodes (waiting while other loads hold it) and the cloud it returns
  /// holds that share until the cloud is destroyed. Must outlive the cloud.
  DecodeBudget* decode_budget = nullptr;
  /// Polled while waiting for decode_budget; true -> boicp::Cancelled. May
  /// be empty (then a load waits until the bytes are free or the budget closes).
  std::function<bool()> decode_stop;
};

/// A file that declares more points than LoadOptions::max_points.
class PointLimitError : public InputError {
 public:
  PointLimitError(const std::string& path, uint64_t points, uint64_t limit);
  uint64_t points() const { return points_; }
  uint64_t limit() const { return limit_; }

 private:
  uint64_t points_, limit_;
};

struct LoadedCloud {
  Points points;                            // finite points only, in the sensor frame, metres
  size_t dropped_nonfinite = 0;             // NaN / inf points removed while loading
  CloudFormat format = CloudFormat::kAuto;  // the format actually used
  /// The cloud's share of LoadOptions::decode_budget (empty without one):
  /// keep the cloud, or move the lease, for as long as its points are kept.
  DecodeBudget::Lease decode_lease;
};

/// An upper bound, in bytes, on what LoadPointCloud(path, options) allocates
/// while it decodes (format buffers and the point arrays), from the file's
/// header or size alone; nothing is decoded (a text file's lines are counted).
/// Throws what LoadPointCloud throws for the header: InputError for a missing
/// or malformed file, PointLimitError over options.max_points.
uint64_t DecodeBoundBytes(const std::string& path, const LoadOptions& options = {});

/// Loads one cloud. Throws PointLimitError over options.max_points, checked
/// against the header before anything is allocated. Throws InputError when the file is missing or
/// unreadable, the format is unknown or malformed (truncated .bin, bad PLY header, PNG that is not
/// 16-bit single channel), depth options are missing, or no finite point is left. With a
/// decode budget: LimitExceeded (naming the file and --max-decode-mb) when the file's
/// DecodeBoundBytes is over the whole budget, Cancelled when options.decode_stop fires or the
/// budget closes while the load waits.
LoadedCloud LoadPointCloud(const std::string& path, const LoadOptions& options = {});

/// Reads a rigid transform from a text file holding 12 (3x4, row-major) or 16
/// (4x4, row-major) numbers. Throws InputError when the file is not that or the
/// rotation part is not orthonormal (tolerance 1e-3).
Transform ReadTransformFile(const std::string& path);

/// Throws InputError naming `what` unless T is a rigid motion: last row
/// 0 0 0 1, rotation orthonormal (tolerance 1e-3), not a reflection.
void RequireRigidTransform(const std::string& what, const Transform& T);

/// Writes points as an ASCII XYZ file, one "x y z" line per point.
void WriteXyz(const std::string& path, const Points& points);

/// The bytes of a binary PCD file of x, y, z as float32 (little-endian), for
/// LoadPointCloud (kPcd) to read back: coordinates rounded to float32, a
/// relative 6e-8 (6 um at 100 m).
std::string EncodeBinaryPcd(const Points& points);

}  // namespace boicp
