#pragma once
// Internal to boicp_core: one opener per bag storage, behind OpenBag.

#include <memory>
#include <string>

#include "boicp/io/bag_reader.hpp"

namespace boicp::io_detail {

/// A ROS 1 .bag file (format 2.0), through rosbag_storage.
std::unique_ptr<BagReader> OpenRos1Bag(const std::string& path, const BagLimits& limits);

/// A ROS 2 sqlite3 storage file (.db3); `path` is the .db3 file itself.
std::unique_ptr<BagReader> OpenRos2SqliteBag(const std::string& path, const BagLimits& limits);

/// A ROS 2 .mcap file, chunked or not, with or without a summary section.
std::unique_ptr<BagReader> OpenMcapBag(const std::string& path, const BagLimits& limits);

}  // namespace boicp::io_detail
