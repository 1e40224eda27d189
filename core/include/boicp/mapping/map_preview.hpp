#pragma once
// A top-down picture of an occupancy map: occupied cells seen from above,
// coloured by height, with the trajectory drawn over them. For a quick look
// at a map, not for measuring.

#include <cstdint>
#include <string>
#include <vector>

#include "boicp/mapping/map_up.hpp"
#include "boicp/util/types.hpp"

namespace boicp {

/// Occupied leaves of an OctoMap: centres (map frame, metres) and edge
/// lengths (pruned leaves are larger than the resolution).
struct OccupiedCells {
  Points centres;
  std::vector<double> sizes;  // metres, one per centre
  double resolution = 0.0;    // metres, the tree's leaf size
};

/// Reads the occupied leaves of a .bt (binary) or .ot (full) OctoMap file.
/// Throws InputError naming the file when it is missing or not an OctoMap.
OccupiedCells ReadOccupiedCells(const std::string& path);

/// An 8-bit RGB image, row-major, 3 bytes per pixel, row 0 at the top.
struct RgbImage {
  int width = 0;
  int height = 0;
  std::vector<uint8_t> pixels;
};

struct PreviewOptions {
  int size_px = 1024;  // the longer side of the image, >= 64
  /// The map's up direction (map frame, non-zero); the picture looks down
  /// along it. z leaves the map's x to the right and y to the top.
  Eigen::Vector3d up = Eigen::Vector3d::UnitZ();
};

/// Renders the cells from above, looking down along -options.up (the map's
/// x, laid flat, to the right), each coloured by its height along up on a
/// blue-to-red scale (the "turbo" colour map, without its dark ends) stretched between
/// the 2nd and 98th percentile of the heights, higher cells over lower ones.
/// A colour bar on the right shows the scale (low at the bottom). The
/// trajectory (positions in the map frame, may be empty) is a white line
/// with a green square at its start and a red one at its end. Throws
/// InputError when there is nothing to draw, size_px < 64 or up is zero.
RgbImage RenderTopDown(const OccupiedCells& cells, const Points& trajectory,
                       const PreviewOptions& options = {});

/// Writes the image as a PNG (Open3D), through a temporary file and a
/// rename. Throws std::runtime_error naming the file on failure.
void WritePng(const std::string& path, const RgbImage& image);

/// ReadOccupiedCells + DetectUp + RenderTopDown along the detected up +
/// WritePng, with the trajectory taken from the translations of `poses`
/// (T_map_scan). Returns the up direction used and why (options.up is
/// ignored).
UpDirection WriteMapPreview(const std::string& octomap_path, const std::vector<Transform>& poses,
                            const std::string& png_path, const PreviewOptions& options = {},
                            const UpDetectionOptions& up_options = {});

}  // namespace boicp
