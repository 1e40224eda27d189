#pragma once
// Internal to boicp_core: one opener per bag storage, behind OpenBag.

#include <memory>
#include <string>
#include <vector>

#include "boicp/io/bag_reader.hpp"

namespace boicp::io_detail {

/// A ROS 1 .bag file (format 2.0), through rosbag_storage.
std::unique_ptr<BagReader> OpenRos1Bag(const std::string& path, const BagLimits& limits);

/// A ROS 2 sqlite3 storage file (.db3); `path` is the .db3 file itself.
std::unique_ptr<BagReader> OpenRos2SqliteBag(const std::string& path, const BagLimits& limits);

/// A ROS 2 .mcap file, chunked or not, with or without a summary section.
std::unique_ptr<BagReader> OpenMcapBag(const std::string& path, const BagLimits& limits);

/// A ROS 2 bag `folder` split into `parts` (its storage files in order, at
/// least one) as one bag. Throws InputError when a topic's type differs
/// between parts.
std::unique_ptr<BagReader> OpenSplitBag(const std::string& folder,
                                        std::vector<std::unique_ptr<BagReader>> parts);

}  // namespace boicp::io_detail
