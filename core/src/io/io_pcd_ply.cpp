// PCD and PLY through Open3D's readers.
//
// Open3D reports most failures by printing a warning and returning false, but
// its LogError throws std::runtime_error, and a failed PLY read can leave
// garbage points behind. So the return value is authoritative, everything
// thrown is converted to InputError, and the header is checked first, to name
// the most common mistakes precisely and to bound what Open3D allocates.
// Open3D's (and RPly's) console warnings are let through: silencing them
// would mean changing global state.

#include <algorithm>
#include <cstring>
#include <map>
#include <optional>
#include <string_view>

#include <open3d/geometry/PointCloud.h>
#include <open3d/io/PointCloudIO.h>

#include "io/io_readers.hpp"

namespace boicp::io_detail {

namespace {

// RPly reads the header as words separated by these (line ends included).
std::vector<std::string_view> PlyWords(std::string_view line) {
  constexpr std::string_view kSeparators = " \t\r";
  std::vector<std::string_view> words;
  for (size_t pos = line.find_first_not_of(kSeparators); pos != std::string_view::npos;) {
    const size_t end = std::min(line.find_first_of(kSeparators, pos), line.size());
    words.push_back(line.substr(pos, end - pos));
    pos = line.find_first_not_of(kSeparators, end);
  }
  return words;
}

// Bytes of a PLY scalar type; 0 for a word that is none.
uint64_t PlyScalarBytes(std::string_view word) {
  static const std::map<std::string_view, uint64_t> kBytes = {
      {"char", 1},   {"uchar", 1},   {"int8", 1},   {"uint8", 1},  {"short", 2}, {"ushort", 2},
      {"int16", 2},  {"uint16", 2},  {"int", 4},    {"uint", 4},   {"float", 4}, {"int32", 4},
      {"uint32", 4}, {"float32", 4}, {"double", 8}, {"float64", 8}};
  const auto it = kBytes.find(word);
  return it == kBytes.end() ? 0 : it->second;
}

bool IsPlyScalarType(std::string_view word) { return PlyScalarBytes(word) != 0; }

bool IsPlyFormatLine(const std::vector<std::string_view>& w) {
  return w.size() == 3 && w[0] == "format" && w[2] == "1.0" &&
         (w[1] == "ascii" || w[1] == "binary_little_endian" || w[1] == "binary_big_endian");
}

bool IsPlyPropertyLine(const std::vector<std::string_view>& w) {
  if (w.size() == 3) return IsPlyScalarType(w[1]);
  return w.size() == 5 && w[1] == "list" && IsPlyScalarType(w[2]) && IsPlyScalarType(w[3]);
}

}  // namespace

// Open3D resizes the cloud to the declared vertex count before RPly reads a
// vertex ("element vertex 2000000000" in a 200-byte file costs 48 GB), and
// RPly itself crashed on headers the fuzzer made up (a comment cut off by the
// end of the file, a bare "property" line). So the header is checked here
// line by line against the PLY grammar, every line whole (RPly reads words
// across line ends), and the vertex count may not exceed the bytes after the
// header, since a vertex takes at least one.
PlyLayout RequirePlyHeaderFits(const std::string& path, uint64_t max_points) {
  constexpr size_t kMaxHeaderLines = 1000;
  constexpr size_t kMaxHeaderLine = 1000;  // RPly's words and lines have fixed buffers
  const auto fail = [&path](const std::string& why) {
    throw InputError(path + ": bad PLY header (" + why + ")");
  };
  std::ifstream in = OpenOrThrow(path, std::ios::in | std::ios::binary);
  std::string line;
  std::getline(in, line);
  if (!line.empty() && line.back() == '\r') line.pop_back();
  if (line != "ply") fail("first line is not 'ply'");
  std::optional<uint64_t> vertices;
  PlyLayout layout;
  bool ascii = false;
  bool in_element = false;
  bool in_vertex = false;
  uint64_t vertex_bytes = 0;  // the least one vertex takes
  for (size_t n = 2; n <= kMaxHeaderLines && std::getline(in, line); ++n) {
    const std::string where = "line " + std::to_string(n);
    if (line.size() > kMaxHeaderLine) fail(where + " too long");
    for (char c : line) {
      if (static_cast<unsigned char>(c) < 0x20 && c != '\t' && c != '\r') {
        fail(where + " has a control byte");
      }
    }
    const std::vector<std::string_view> words = PlyWords(line);
    if (n == 2 && !IsPlyFormatLine(words)) fail("line 2 is not 'format <ascii|binary_*> 1.0'");
    if (n == 2) ascii = words[1] == "ascii";
    if (n == 2 || words.empty() || words[0] == "comment" || words[0] == "obj_info") continue;
    if (words[0] == "end_header" && words.size() == 1) {
      const uint64_t size = FileSizeOrThrow(path);
      const uint64_t data = in.eof() ? 0 : size - static_cast<uint64_t>(in.tellg());
      if (vertices && *vertices > data / std::max<uint64_t>(vertex_bytes, 1)) {
        throw InputError(path + ": truncated PLY (" + std::to_string(*vertices) +
                         " vertices of at least " + std::to_string(vertex_bytes) +
                         " bytes declared, " + std::to_string(data) + " data bytes)");
      }
      if (vertices) RequirePointCount(path, *vertices, max_points);
      layout.vertices = vertices.value_or(0);
      return layout;
    }
    if (words[0] == "property" && in_element && IsPlyPropertyLine(words)) {
      if (!in_vertex) continue;
      vertex_bytes += ascii ? 2 : PlyScalarBytes(words[words.size() == 3 ? 1 : 2]);
      const std::string_view name = words.back();
      // Open3D sizes normals and colours to the vertex count when it finds them.
      layout.normals = layout.normals || name == "nx" || name == "ny" || name == "nz";
      layout.colors = layout.colors || name == "red" || name == "green" || name == "blue";
      continue;
    }
    const std::optional<double> count =
        words.size() == 3 && words[0] == "element" ? ParseNumber(words[2]) : std::nullopt;
    if (!count || !(*count >= 0.0 && *count < 1e15) ||
        *count != static_cast<double>(static_cast<uint64_t>(*count))) {
      fail(where + " is not a format, comment, element, property or end_header line");
    }
    in_element = true;
    in_vertex = words[1] == "vertex";
    if (!in_vertex) continue;
    if (vertices) fail("two vertex elements");
    vertices = static_cast<uint64_t>(*count);
  }
  throw InputError(path + ": bad PLY header (no end_header line)");
}

Points ReadPcdOrPly(const std::string& path, CloudFormat format, uint64_t max_points) {
  const bool is_ply = format == CloudFormat::kPly;
  const std::string name = is_ply ? "PLY" : "PCD";
  if (is_ply) {
    RequirePlyHeaderFits(path, max_points);
  } else {
    RequireSafePcdHeader(path, max_points);
  }

  open3d::io::ReadPointCloudOption option;
  option.format = is_ply ? "ply" : "pcd";
  // Keep NaN / inf points so that LoadPointCloud can count what it drops.
  option.remove_nan_points = false;
  option.remove_infinite_points = false;
  option.print_progress = false;

  open3d::geometry::PointCloud cloud;
  bool ok = false;
  try {
    ok = open3d::io::ReadPointCloud(path, cloud, option);
  } catch (const std::exception& e) {
    throw InputError(path + ": cannot read " + name + " (" + e.what() + ")");
  } catch (...) {
    throw InputError(path + ": cannot read " + name + " (unknown Open3D error)");
  }
  if (!ok) {
    throw InputError(path + ": cannot read " + name +
                     " (bad header, no x/y/z vertices, or truncated data)");
  }
  return std::move(cloud.points_);
}

}  // namespace boicp::io_detail

namespace boicp {

std::string EncodeBinaryPcd(const Points& points) {
  const std::string n = std::to_string(points.size());
  std::string bytes =
      "# .PCD v0.7 - Point Cloud Data file format\nVERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\n"
      "TYPE F F F\nCOUNT 1 1 1\nWIDTH " +
      n + "\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS " + n + "\nDATA binary\n";
  size_t at = bytes.size();
  bytes.resize(at + points.size() * 3 * sizeof(float));
  // The hosts boicp runs on are little-endian, as PCD's binary data is.
  for (const Point& p : points) {
    const float xyz[3] = {static_cast<float>(p.x()), static_cast<float>(p.y()),
                          static_cast<float>(p.z())};
    std::memcpy(&bytes[at], xyz, sizeof xyz);
    at += sizeof xyz;
  }
  return bytes;
}

}  // namespace boicp
