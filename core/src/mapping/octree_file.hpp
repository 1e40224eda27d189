#pragma once
// Reading an OctoMap file (.bt or .ot) written by OccupancyMap, quietly and
// safely: OctoMap's own readers print "Reading ... octree type" lines on
// stderr, and build garbage (with a cost that can grow exponentially) from a
// file cut short, because they never check the stream while they recurse.

#include <octomap/OcTree.h>

#include <memory>
#include <string>

namespace boicp {

/// Reads the OcTree at `path`. Throws InputError naming the file when it
/// cannot be opened, is not an OctoMap OcTree, or its node data is cut short
/// or malformed.
std::unique_ptr<octomap::OcTree> ReadOctreeFile(const std::string& path);

}  // namespace boicp
