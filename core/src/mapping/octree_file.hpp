#pragma once
// OctoMap files (.bt or .ot), read and written quietly and safely: OctoMap's
// own readers print "Reading ... octree type" lines on stderr, and build
// garbage (with a cost that can grow exponentially) from a file cut short,
// because they never check the stream while they recurse; its .bt writer
// prints " done." on stderr.

#include <octomap/OcTree.h>

#include <memory>
#include <ostream>
#include <string>

namespace boicp {

/// Reads the OcTree at `path`. Throws InputError naming the file when it
/// cannot be opened, is not an OctoMap OcTree, or its node data is cut short
/// or malformed.
std::unique_ptr<octomap::OcTree> ReadOctreeFile(const std::string& path);

/// Writes `tree` to `out` as a .bt (header, then OctoMap's binary node data),
/// the bytes OcTree::writeBinary writes: like it, first turns the tree into
/// its maximum-likelihood form and prunes it. Returns whether `out` is good.
bool WriteBinaryOctree(octomap::OcTree& tree, std::ostream& out);

}  // namespace boicp
