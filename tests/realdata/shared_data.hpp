#pragma once
// Where the real-data tests find ../shared/data, and how its scans load.

#include <cctype>
#include <filesystem>
#include <string>

#include "boicp/io/point_cloud_io.hpp"

namespace boicp {

/// The folder of dataset `name` under the shared data (BOICP_SHARED_DATA_DIR).
inline std::filesystem::path SharedDataFolder(const std::string& name) {
  return std::filesystem::path(BOICP_SHARED_DATA_DIR) / name;
}

/// Why a test skips when `folder` holds no pairs.csv, or empty when it does.
inline std::string MissingSharedData(const std::filesystem::path& folder) {
  if (std::filesystem::exists(folder / "pairs.csv")) return "";
  return "real data not found at " + folder.string() +
         " (../shared/data beside the project root); skipping";
}

/// How the dataset's scans load: 7-Scenes depth PNGs are 1000 units a metre,
/// with the folder's camera-intrinsics.txt; other formats need nothing.
inline LoadOptions SharedDataLoadOptions(const std::filesystem::path& folder, bool depth_images) {
  LoadOptions load;
  if (depth_images) {
    load.depth.intrinsics = ReadIntrinsicsFile((folder / "camera-intrinsics.txt").string());
    load.depth.depth_scale = 1000.0;
  }
  return load;
}

/// `name` as a test name: every character but letters and digits becomes '_'.
inline std::string TestName(std::string name) {
  for (char& c : name) {
    if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
  }
  return name;
}

}  // namespace boicp
