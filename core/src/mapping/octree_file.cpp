#include "mapping/octree_file.hpp"

#include <cstdint>
#include <fstream>
#include <iterator>
#include <sstream>

#include "io/io_readers.hpp"

namespace boicp {
namespace {

constexpr size_t kCutShort = std::string::npos;
constexpr int kTreeDepth = 16;  // OctoMap's fixed depth: no node lies deeper

struct OctreeHeader {
  std::string id;
  size_t size = 0;  // nodes; 0 = an empty tree, with no node data
  double resolution = 0.0;
  bool complete = false;  // "data" reached after an id and a positive resolution
};

OctreeHeader ReadHeader(std::istream& in) {
  OctreeHeader header;
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream fields(line);
    std::string key;
    fields >> key;
    if (key == "id") {
      fields >> header.id;
    } else if (key == "size") {
      fields >> header.size;
    } else if (key == "res") {
      fields >> header.resolution;
    } else if (key == "data") {
      header.complete = !header.id.empty() && header.resolution > 0.0;
      break;
    }
  }
  return header;
}

// The two formats' node layouts, walked without building anything: each
// returns the offset just past the node at `offset` and its subtree, or
// kCutShort when the data ends first or nests deeper than the tree can.

// .bt: two bytes of 2-bit child codes (free leaf, occupied leaf, inner node),
// then the inner children in order.
size_t SkipBinaryNode(const std::string& data, size_t offset, int depth) {
  if (depth > kTreeDepth || offset + 2 > data.size()) return kCutShort;
  const uint16_t codes = static_cast<uint8_t>(data[offset]) |
                         static_cast<uint16_t>(static_cast<uint8_t>(data[offset + 1]) << 8);
  offset += 2;
  for (int child = 0; child < 8 && offset != kCutShort; ++child) {
    if (((codes >> (2 * child)) & 3u) == 3u) offset = SkipBinaryNode(data, offset, depth + 1);
  }
  return offset;
}

// .ot: the node's log-odds (float), a byte with one bit per child, then the
// children in order.
size_t SkipFullNode(const std::string& data, size_t offset, int depth) {
  const size_t node_bytes = sizeof(float) + 1;
  if (depth > kTreeDepth || offset + node_bytes > data.size()) return kCutShort;
  const auto children = static_cast<uint8_t>(data[offset + sizeof(float)]);
  offset += node_bytes;
  for (int child = 0; child < 8 && offset != kCutShort; ++child) {
    if ((children >> child) & 1u) offset = SkipFullNode(data, offset, depth + 1);
  }
  return offset;
}

}  // namespace

bool WriteBinaryOctree(octomap::OcTree& tree, std::ostream& out) {
  tree.toMaxLikelihood();
  tree.prune();
  out << "# Octomap OcTree binary file\n"
      << "# (feel free to add / change comments, but leave the first line as it is!)\n#\n"
      << "id " << tree.getTreeType() << "\nsize " << tree.size() << "\nres " << tree.getResolution()
      << "\ndata\n";
  tree.writeBinaryData(out);
  return out.good();
}

std::unique_ptr<octomap::OcTree> ReadOctreeFile(const std::string& path) {
  std::ifstream in = io_detail::OpenOrThrow(path, std::ios::binary);
  std::string first_line;
  std::getline(in, first_line);
  const bool binary = first_line.rfind("# Octomap OcTree binary file", 0) == 0;
  if (!binary && first_line.rfind("# Octomap OcTree file", 0) != 0) {
    throw InputError(path + ": not an OctoMap file (.bt or .ot)");
  }
  const OctreeHeader header = ReadHeader(in);
  if (!header.complete) throw InputError(path + ": the OctoMap header is incomplete");
  if (header.id != "OcTree") {
    throw InputError(path + ": not an OctoMap OcTree (type " + header.id + ")");
  }
  auto tree = std::make_unique<octomap::OcTree>(header.resolution);
  if (header.size == 0) return tree;

  const std::string data{std::istreambuf_iterator<char>(in), {}};
  const size_t end = binary ? SkipBinaryNode(data, 0, 0) : SkipFullNode(data, 0, 0);
  if (end == kCutShort) throw InputError(path + ": the OctoMap data is cut short or malformed");
  std::istringstream nodes(data);
  if (binary) {
    tree->readBinaryData(nodes);
  } else {
    tree->readData(nodes);
  }
  return tree;
}

}  // namespace boicp
