// A strict check of a PCD header, run before Open3D reads the file.
//
// Open3D's PCD reader trusts its header: it resizes the cloud to POINTS and
// allocates the compressed and uncompressed sizes of binary_compressed data
// before reading a byte of it (a 200-byte file can ask for 4 GB), it decodes
// binary coordinates it does not know (F8 doubles) as silent zeros, and it
// matches keywords by prefix. So the header is parsed here by the PCD v0.7
// rules, and every declared size must fit in the bytes the file holds. A
// header that passes is read the same way by Open3D.

#include <algorithm>
#include <cstdint>
#include <initializer_list>
#include <limits>
#include <map>
#include <optional>

#include "io/io_readers.hpp"

namespace boicp::io_detail {

namespace {

// Open3D reads header lines with fgets into a 1024-byte buffer; longer lines
// would be split differently by the two parsers.
constexpr size_t kMaxHeaderLine = 1000;
constexpr size_t kMaxHeaderLines = 64;
// Open3D decodes binary data whole before it keeps x/y/z, so its memory is
// POINTS x the point's size. Scans carry a few fields (x, y, z, intensity,
// ring, time, PCL's padding: 16-48 bytes); 64 bounds a 5 M-point scan's
// decoding to 320 MB, where COUNT padding could otherwise ask for 2 GB.
constexpr uint64_t kMaxBinaryPointBytes = 64;
// Point data compresses a few times at most (coordinates hardly at all); an
// LZF back-reference could copy 264 bytes from 3, so a file of zeros would
// otherwise decode to 88 times its size.
constexpr uint64_t kMaxCompressedExpansion = 16;
// Open3D indexes the data with int arithmetic.
constexpr uint64_t kMaxDataBytes = static_cast<uint64_t>(std::numeric_limits<int>::max());

struct PcdField {
  std::string name;
  int size = 4;
  char type = 'F';
  int count = 1;
};

struct PcdHeader {
  std::vector<PcdField> fields;
  std::map<std::string, std::vector<std::string>> lines;  // keyword -> its values
  uint64_t points = 0;
  uint64_t point_bytes = 0;
  std::string data;
};

[[noreturn]] void Fail(const std::string& path, const std::string& why) {
  throw InputError(path + ": bad PCD (" + why + ")");
}

// Splits on the separators Open3D's PCD reader uses (not SplitFields' commas).
std::vector<std::string_view> Tokens(std::string_view line) {
  constexpr std::string_view kSeparators = " \t\r";
  std::vector<std::string_view> tokens;
  for (size_t pos = line.find_first_not_of(kSeparators); pos != std::string_view::npos;) {
    const size_t end = std::min(line.find_first_of(kSeparators, pos), line.size());
    tokens.push_back(line.substr(pos, end - pos));
    pos = line.find_first_not_of(kSeparators, end);
  }
  return tokens;
}

std::optional<uint64_t> ParseCount(const std::string& token) {
  if (token.empty() || token.size() > 9) return std::nullopt;
  uint64_t value = 0;
  for (char c : token) {
    if (c < '0' || c > '9') return std::nullopt;
    value = value * 10 + static_cast<uint64_t>(c - '0');
  }
  return value;
}

uint64_t CountOrFail(const std::string& path, const std::string& keyword,
                     const std::string& token) {
  const std::optional<uint64_t> value = ParseCount(token);
  if (!value) Fail(path, keyword + " '" + token.substr(0, 20) + "' is not a whole number");
  return *value;
}

// The keyword's values, which must number `expected` (0: any, at least one).
const std::vector<std::string>& Values(const std::string& path, const PcdHeader& header,
                                       const std::string& keyword, size_t expected) {
  const auto it = header.lines.find(keyword);
  if (it == header.lines.end()) Fail(path, "no " + keyword + " line");
  if (it->second.empty() || (expected != 0 && it->second.size() != expected)) {
    Fail(path,
         keyword + " needs " + (expected != 0 ? std::to_string(expected) + " values" : "values"));
  }
  return it->second;
}

// True for bytes Open3D and this parser could split differently.
bool HasControlByte(const std::string& line) {
  for (char c : line) {
    if (static_cast<unsigned char>(c) < 0x20 && c != '\t' && c != '\r') return true;
  }
  return false;
}

// Reads header lines up to and including DATA, keywords in the order PCD v0.7
// prescribes (Open3D evaluates WIDTH, HEIGHT and COUNT in file order); returns
// the data offset.
uint64_t ReadHeaderLines(const std::string& path, PcdHeader* header) {
  static const std::vector<std::string> kKeywords = {"VERSION", "FIELDS", "SIZE",   "TYPE",
                                                     "COUNT",   "WIDTH",  "HEIGHT", "VIEWPOINT",
                                                     "POINTS",  "DATA"};
  std::ifstream in = OpenOrThrow(path, std::ios::in | std::ios::binary);
  std::string line;
  size_t next_keyword = 0;
  for (size_t n = 0; n < kMaxHeaderLines && std::getline(in, line); ++n) {
    if (line.size() > kMaxHeaderLine) Fail(path, "line " + std::to_string(n + 1) + " too long");
    if (HasControlByte(line)) Fail(path, "control byte in line " + std::to_string(n + 1));
    const std::vector<std::string_view> tokens = Tokens(line);
    if (tokens.empty() || tokens[0][0] == '#') continue;
    const std::string keyword = tokens[0] == "COLUMNS" ? "FIELDS" : std::string(tokens[0]);
    size_t index = next_keyword;
    while (index < kKeywords.size() && kKeywords[index] != keyword) ++index;
    if (index == kKeywords.size()) {
      Fail(path,
           "unexpected line '" + line.substr(0, 20) + "' (unknown, repeated or out of order)");
    }
    next_keyword = index + 1;
    header->lines[keyword].assign(tokens.begin() + 1, tokens.end());
    if (keyword != "DATA") continue;
    if (in.eof()) return FileSizeOrThrow(path);
    return static_cast<uint64_t>(in.tellg());
  }
  Fail(path, "no DATA line in the first " + std::to_string(kMaxHeaderLines) + " lines");
}

void ParseFields(const std::string& path, PcdHeader* header) {
  const std::vector<std::string>& names = Values(path, *header, "FIELDS", 0);
  const size_t n = names.size();
  const std::vector<std::string>& sizes = Values(path, *header, "SIZE", n);
  const std::vector<std::string>& types = Values(path, *header, "TYPE", n);
  const bool has_count = header->lines.count("COUNT") != 0;
  for (size_t i = 0; i < n; ++i) {
    PcdField field;
    field.name = names[i];
    const uint64_t size = CountOrFail(path, "SIZE", sizes[i]);
    if (size != 1 && size != 2 && size != 4 && size != 8) Fail(path, "SIZE must be 1, 2, 4 or 8");
    field.size = static_cast<int>(size);
    if (types[i] != "F" && types[i] != "I" && types[i] != "U") Fail(path, "TYPE must be F, I or U");
    field.type = types[i][0];
    if (has_count) {
      const uint64_t count = CountOrFail(path, "COUNT", Values(path, *header, "COUNT", n)[i]);
      if (count < 1 || count > 4096) Fail(path, "COUNT must be 1..4096");
      field.count = static_cast<int>(count);
    }
    header->point_bytes += static_cast<uint64_t>(field.size) * static_cast<uint64_t>(field.count);
    header->fields.push_back(field);
  }
}

// Open3D turns binary coordinates it cannot decode into zeros; refuse them.
void RequireDecodableXyz(const std::string& path, const PcdHeader& header) {
  int found = 0;
  for (const PcdField& f : header.fields) {
    if (f.name != "x" && f.name != "y" && f.name != "z") continue;
    ++found;
    const bool decodable = f.type == 'F' ? f.size == 4 : f.size <= 4;
    if (header.data != "ascii" && !decodable) {
      Fail(path, "field " + f.name + " is " + std::string(1, f.type) + std::to_string(f.size) +
                     "; binary x/y/z must be F4, I1/I2/I4 or U1/U2/U4");
    }
  }
  if (found != 3) Fail(path, "FIELDS must name x, y and z once each");
}

void ParseSizes(const std::string& path, PcdHeader* header) {
  const uint64_t width = CountOrFail(path, "WIDTH", Values(path, *header, "WIDTH", 1)[0]);
  const uint64_t height = CountOrFail(path, "HEIGHT", Values(path, *header, "HEIGHT", 1)[0]);
  header->points = CountOrFail(path, "POINTS", Values(path, *header, "POINTS", 1)[0]);
  if (header->points == 0) Fail(path, "POINTS is 0");
  if (width * height != header->points) Fail(path, "WIDTH x HEIGHT differs from POINTS");
  header->data = Values(path, *header, "DATA", 1)[0];
  if (header->data != "ascii" && header->data != "binary" && header->data != "binary_compressed") {
    Fail(path, "DATA must be ascii, binary or binary_compressed");
  }
}

uint32_t LittleEndianU32(const unsigned char* bytes) {
  return uint32_t{bytes[0]} | uint32_t{bytes[1]} << 8 | uint32_t{bytes[2]} << 16 |
         uint32_t{bytes[3]} << 24;
}

// Open3D skips data lines with too few values and leaves the points it did
// not fill at (0, 0, 0); so every declared point needs its own line here.
void RequireAsciiPointLines(const std::string& path, const PcdHeader& header,
                            uint64_t data_offset) {
  size_t values_per_point = 0;
  for (const PcdField& f : header.fields) values_per_point += static_cast<size_t>(f.count);
  std::ifstream in = OpenOrThrow(path, std::ios::in | std::ios::binary);
  in.seekg(static_cast<std::streamoff>(data_offset));
  uint64_t point_lines = 0;
  std::string line;
  while (point_lines < header.points && std::getline(in, line)) {
    if (line.size() > kMaxHeaderLine || HasControlByte(line)) {
      Fail(path, "ascii data line " + std::to_string(point_lines + 1) + " is malformed");
    }
    const std::vector<std::string_view> tokens = Tokens(line);
    if (tokens.size() < values_per_point) continue;
    for (size_t i = 0; i < values_per_point; ++i) {
      if (!ParseNumber(tokens[i])) {
        Fail(path, "ascii point " + std::to_string(point_lines + 1) + ": '" +
                       std::string(tokens[i].substr(0, 20)) + "' is not a number");
      }
    }
    ++point_lines;
  }
  if (point_lines < header.points) {
    throw InputError(path + ": truncated PCD (POINTS " + std::to_string(header.points) + ", " +
                     std::to_string(point_lines) + " complete point lines)");
  }
}

// Every size the header declares must fit in the `available` bytes after it;
// returns the compressed bytes of binary_compressed data (0 otherwise).
uint64_t RequireDataFits(const std::string& path, const PcdHeader& header, uint64_t data_offset,
                         uint64_t available) {
  const uint64_t declared = header.points * header.point_bytes;
  if (declared > kMaxDataBytes) Fail(path, "POINTS x point size is over 2 GB");
  if (header.data == "ascii") return 0;
  if (header.point_bytes > kMaxBinaryPointBytes) {
    Fail(path, "binary points of " + std::to_string(header.point_bytes) + " bytes; at most " +
                   std::to_string(kMaxBinaryPointBytes) +
                   " are read (keep x, y, z and a few fields, or write ascii)");
  }
  if (header.data == "binary") {
    if (declared > available) {
      throw InputError(path + ": truncated PCD (" + std::to_string(declared) +
                       " data bytes declared, " + std::to_string(available) + " present)");
    }
    return 0;
  }
  std::ifstream in = OpenOrThrow(path, std::ios::in | std::ios::binary);
  in.seekg(static_cast<std::streamoff>(data_offset));
  unsigned char sizes[8] = {};
  if (available < 8 || !in.read(reinterpret_cast<char*>(sizes), sizeof(sizes))) {
    throw InputError(path + ": truncated PCD (no binary_compressed sizes)");
  }
  const uint64_t compressed = LittleEndianU32(sizes);
  const uint64_t uncompressed = LittleEndianU32(sizes + 4);
  if (compressed > available - 8) {
    throw InputError(path + ": truncated PCD (" + std::to_string(compressed) +
                     " compressed bytes declared, " + std::to_string(available - 8) + " present)");
  }
  if (uncompressed != declared) {
    Fail(path, "binary_compressed sizes do not match POINTS and the fields");
  }
  if (uncompressed > kMaxCompressedExpansion * compressed) {
    Fail(path, "binary_compressed data would expand " +
                   std::to_string(uncompressed / std::max<uint64_t>(compressed, 1)) +
                   " times; at most " + std::to_string(kMaxCompressedExpansion) + " is accepted");
  }
  return compressed;
}

bool HasField(const PcdHeader& header, std::initializer_list<const char*> names) {
  return std::any_of(header.fields.begin(), header.fields.end(), [&](const PcdField& f) {
    return std::find(names.begin(), names.end(), f.name) != names.end();
  });
}

// The header checked up to the data, which ascii files still need checked.
PcdHeader ReadCheckedHeader(const std::string& path, uint64_t max_points, PcdLayout* layout,
                            uint64_t* data_offset) {
  PcdHeader header;
  *data_offset = ReadHeaderLines(path, &header);
  const uint64_t file_size = FileSizeOrThrow(path);
  ParseFields(path, &header);
  ParseSizes(path, &header);
  RequireDecodableXyz(path, header);
  layout->compressed_bytes = RequireDataFits(path, header, *data_offset, file_size - *data_offset);
  RequirePointCount(path, header.points, max_points);
  layout->points = header.points;
  layout->point_bytes = header.point_bytes;
  layout->ascii = header.data == "ascii";
  layout->compressed = header.data == "binary_compressed";
  // Open3D sizes normals and colours to POINTS when the header names them.
  layout->normals = HasField(header, {"normal_x", "normal_y", "normal_z"});
  layout->colors = HasField(header, {"rgb", "rgba"});
  return header;
}

}  // namespace

PcdLayout ReadPcdLayout(const std::string& path, uint64_t max_points) {
  PcdLayout layout;
  uint64_t data_offset = 0;
  ReadCheckedHeader(path, max_points, &layout, &data_offset);
  return layout;
}

void RequireSafePcdHeader(const std::string& path, uint64_t max_points) {
  PcdLayout layout;
  uint64_t data_offset = 0;
  const PcdHeader header = ReadCheckedHeader(path, max_points, &layout, &data_offset);
  if (layout.ascii) RequireAsciiPointLines(path, header, data_offset);
}

}  // namespace boicp::io_detail
