#pragma once
// Small files whose headers declare far more points than a daemon or the CLI
// should ever allocate: a loader must refuse each from its header. Also how
// much memory a child process peaked at. Header-only; the PNG needs zlib.

#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>
#include <zlib.h>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

namespace boicp::test {

struct MemoryBomb {
  std::string name;       // for messages
  std::string file_name;  // the extension tells the CLI the format
  uint64_t declared_points = 0;
  std::string refusal;  // what refuses it, when not the 5 M-point limit
};

inline void AppendLittleEndianU32(std::string* out, uint32_t v) {
  for (int i = 0; i < 4; ++i) out->push_back(static_cast<char>((v >> (8 * i)) & 0xff));
}

inline void AppendBigEndianU32(std::string* out, uint32_t v) {
  for (int i = 3; i >= 0; --i) out->push_back(static_cast<char>((v >> (8 * i)) & 0xff));
}

/// An LZF back-reference copying the byte before `length` (3..264) times.
inline void AppendLzfRepeatOfPreviousByte(std::string* lzf, uint64_t length) {
  if (length - 2 < 7) {
    lzf->push_back(static_cast<char>((length - 2) << 5));
  } else {
    lzf->push_back(static_cast<char>(0xE0));
    lzf->push_back(static_cast<char>(length - 2 - 7));
  }
  lzf->push_back('\0');  // offset 0: the byte before
}

/// LZF data that decodes to `size` zero bytes: a one-byte literal, then
/// back-references to the byte before (3 bytes each for 264 bytes, LZF's
/// best), and a literal for what remains. About 88 times smaller than decoded.
inline std::string LzfZeros(uint64_t size) {
  std::string lzf(2, '\0');  // literal run of one zero
  uint64_t left = size - 1;
  while (left >= 3) {
    uint64_t length = std::min<uint64_t>(264, left);
    if (left - length > 0 && left - length < 3) length = left - 3;
    AppendLzfRepeatOfPreviousByte(&lzf, length);
    left -= length;
  }
  if (left > 0) {
    lzf.push_back(static_cast<char>(left - 1));
    lzf.append(left, '\0');
  }
  return lzf;
}

/// LZF data that decodes to `size` zero bytes about 8 times smaller, within
/// the loaders' 16x: runs of 32 literal zeros, each followed by a
/// back-reference copying 264 more.
inline std::string LzfZerosEightfold(uint64_t size) {
  std::string lzf;
  for (uint64_t left = size; left > 0;) {
    const uint64_t literal = std::min<uint64_t>(32, left);
    lzf.push_back(static_cast<char>(literal - 1));
    lzf.append(literal, '\0');
    left -= literal;
    if (left < 3) continue;
    const uint64_t length = std::min<uint64_t>(264, left);
    AppendLzfRepeatOfPreviousByte(&lzf, length);
    left -= length;
  }
  return lzf;
}

/// A binary_compressed PCD that loads: `points` points at the origin, 64
/// bytes each (1-byte coordinates and 61 bytes of padding, the most the
/// loaders accept), compressed about 8 times. Decoding it takes about 96
/// bytes a point (DecodeBoundBytes): the compressed and inflated data, and
/// the points.
inline void WriteDecodablePaddedPcd(const std::filesystem::path& path, uint64_t points) {
  const uint64_t raw = 64 * points;
  const std::string data = LzfZerosEightfold(raw);
  std::string text =
      "VERSION .7\nFIELDS x y z _\nSIZE 1 1 1 1\nTYPE U U U U\nCOUNT 1 1 1 61\n"
      "WIDTH " +
      std::to_string(points) + "\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS " +
      std::to_string(points) + "\nDATA binary_compressed\n";
  AppendLittleEndianU32(&text, static_cast<uint32_t>(data.size()));
  AppendLittleEndianU32(&text, static_cast<uint32_t>(raw));
  text += data;
  std::ofstream(path, std::ios::binary) << text;
}

/// binary_compressed PCD of 1-byte coordinates and `padding` more bytes a
/// point (a COUNT). Its data is real LZF, `expansion` times smaller than
/// decoded; 88 is LZF's most (LzfZeros), less pads the data with zeros.
inline void WritePcdBomb(const std::filesystem::path& path, uint64_t points, uint64_t padding,
                         uint64_t expansion) {
  const uint64_t raw = (3 + padding) * points;
  std::string data = LzfZeros(raw);
  if (data.size() < raw / expansion) data.resize(raw / expansion, '\0');
  const bool padded = padding > 0;
  std::string text = std::string("VERSION .7\nFIELDS x y z") + (padded ? " _" : "") +
                     "\nSIZE 1 1 1" + (padded ? " 1" : "") + "\nTYPE U U U" + (padded ? " U" : "") +
                     "\nCOUNT 1 1 1" + (padded ? " " + std::to_string(padding) : "") + "\nWIDTH " +
                     std::to_string(points) + "\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS " +
                     std::to_string(points) + "\nDATA binary_compressed\n";
  AppendLittleEndianU32(&text, static_cast<uint32_t>(data.size()));
  AppendLittleEndianU32(&text, static_cast<uint32_t>(raw));
  text += data;
  std::ofstream(path, std::ios::binary) << text;
}

/// Binary PLY declaring `vertices` of three 1-byte coordinates (Open3D
/// allocates 72 bytes each) followed by `data_bytes` bytes.
inline void WritePlyBomb(const std::filesystem::path& path, uint64_t vertices,
                         uint64_t data_bytes) {
  std::string text = "ply\nformat binary_little_endian 1.0\nelement vertex " +
                     std::to_string(vertices) +
                     "\nproperty uchar x\nproperty uchar y\nproperty uchar z\nend_header\n";
  text.append(data_bytes, '\1');
  std::ofstream(path, std::ios::binary) << text;
}

inline void AppendPngChunk(std::string* out, const char* type, const std::string& data) {
  AppendBigEndianU32(out, static_cast<uint32_t>(data.size()));
  const std::string typed = std::string(type, 4) + data;
  out->append(typed);
  AppendBigEndianU32(out,
                     static_cast<uint32_t>(crc32(0, reinterpret_cast<const Bytef*>(typed.data()),
                                                 static_cast<uInt>(typed.size()))));
}

/// A side x side 16-bit grey PNG, every pixel a valid depth: side^2 points.
inline void WriteDepthPngBomb(const std::filesystem::path& path, uint32_t side) {
  std::string header;
  AppendBigEndianU32(&header, side);
  AppendBigEndianU32(&header, side);
  header +=
      std::string("\x10\x00\x00\x00\x00", 5);  // 16-bit, grey, deflate, no filter, no interlace
  std::vector<unsigned char> row(1 + 2 * static_cast<size_t>(side), 0);
  for (size_t i = 1; i < row.size(); i += 2) row[i] = 0x03, row[i + 1] = 0xe8;  // 1000
  z_stream z{};
  deflateInit(&z, 9);
  std::string idat;
  std::vector<unsigned char> out(1 << 16);
  for (uint32_t r = 0; r < side; ++r) {
    z.next_in = row.data();
    z.avail_in = static_cast<uInt>(row.size());
    const int flush = r + 1 == side ? Z_FINISH : Z_NO_FLUSH;
    do {
      z.next_out = out.data();
      z.avail_out = static_cast<uInt>(out.size());
      deflate(&z, flush);
      idat.append(reinterpret_cast<char*>(out.data()), out.size() - z.avail_out);
    } while (z.avail_out == 0);
  }
  deflateEnd(&z);
  std::string png = "\x89PNG\r\n\x1a\n";
  AppendPngChunk(&png, "IHDR", header);
  AppendPngChunk(&png, "IDAT", idat);
  AppendPngChunk(&png, "IEND", "");
  std::ofstream(path, std::ios::binary) << png;
}

/// KITTI rows (16 bytes each) at (1, 1, 1).
inline void WriteKittiBomb(const std::filesystem::path& path, uint64_t rows) {
  std::ofstream file(path, std::ios::binary);
  const float row[4] = {1.0f, 1.0f, 1.0f, 0.0f};
  std::string block;
  for (int i = 0; i < 4096; ++i) block.append(reinterpret_cast<const char*>(row), sizeof(row));
  for (uint64_t done = 0; done < rows; done += 4096) {
    file.write(block.data(),
               static_cast<std::streamsize>(std::min<uint64_t>(4096, rows - done) * 16));
  }
}

/// XYZ text, six bytes a point.
inline void WriteXyzBomb(const std::filesystem::path& path, uint64_t points) {
  std::ofstream file(path, std::ios::binary);
  std::string block;
  for (int i = 0; i < 4096; ++i) block += "1 1 1\n";
  for (uint64_t done = 0; done < points; done += 4096) {
    file.write(block.data(),
               static_cast<std::streamsize>(std::min<uint64_t>(4096, points - done) * 6));
  }
}

/// Every bomb, written into `dir`. Most declare over 5 M points (the default
/// limit); two declare fewer and would still make Open3D allocate hundreds of
/// megabytes: 420-byte padded PCD points compressed 88 times (420 MB from
/// 5 MB), and PLY vertices one byte of data each (72 bytes each once read).
inline std::vector<MemoryBomb> WriteMemoryBombs(const std::filesystem::path& dir) {
  constexpr uint32_t kPngSide = 8192;
  WritePcdBomb(dir / "bomb.pcd", 6000000, 0, 16);
  WritePcdBomb(dir / "padded.pcd", 1000000, 417, 88);
  WritePlyBomb(dir / "bomb.ply", 6000000, 18000000);
  WritePlyBomb(dir / "short.ply", 4000000, 4000000);
  WriteDepthPngBomb(dir / "bomb.png", kPngSide);
  WriteKittiBomb(dir / "bomb.bin", 10000000);
  WriteXyzBomb(dir / "bomb.xyz", 10000000);
  return {{"binary_compressed PCD", "bomb.pcd", 6000000, ""},
          {"padded binary_compressed PCD", "padded.pcd", 1000000,
           "binary points of 420 bytes; at most 64"},
          {"PLY", "bomb.ply", 6000000, ""},
          {"PLY short of its vertices", "short.ply", 4000000,
           "4000000 vertices of at least 3 bytes declared"},
          {"depth PNG", "bomb.png", uint64_t{kPngSide} * kPngSide, ""},
          {"KITTI .bin", "bomb.bin", 10000000, ""},
          {"XYZ text", "bomb.xyz", 10000000, ""}};
}

struct MeasuredRun {
  int exit_code = -1;
  uint64_t peak_rss_mb = 0;
  std::string err;
};

/// Runs `argv` as a child with stdout discarded and stderr in `err_path`;
/// returns its exit code and peak resident memory (ru_maxrss of the child).
inline MeasuredRun RunMeasured(const std::vector<std::string>& argv,
                               const std::filesystem::path& err_path) {
  std::fflush(nullptr);  // else the child's freopen writes the parent's buffered output again
  const pid_t pid = ::fork();
  if (pid == 0) {
    if (!std::freopen("/dev/null", "w", stdout) || !std::freopen(err_path.c_str(), "w", stderr)) {
      ::_exit(127);
    }
    std::vector<char*> args;
    for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
    args.push_back(nullptr);
    ::execv(args[0], args.data());
    ::_exit(127);
  }
  MeasuredRun run;
  int status = 0;
  struct rusage usage {};
  if (pid < 0 || ::wait4(pid, &status, 0, &usage) != pid) return run;
  run.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  run.peak_rss_mb = static_cast<uint64_t>(usage.ru_maxrss) / 1024;
  std::ifstream err(err_path);
  run.err.assign(std::istreambuf_iterator<char>(err), std::istreambuf_iterator<char>());
  return run;
}

/// Peak resident memory of a running process (VmHWM), in MB; 0 if unknown.
inline uint64_t PeakRssMb(pid_t pid) {
  std::ifstream status("/proc/" + std::to_string(pid) + "/status");
  std::string line;
  while (std::getline(status, line)) {
    if (line.rfind("VmHWM:", 0) == 0) return std::stoull(line.substr(6)) / 1024;
  }
  return 0;
}

}  // namespace boicp::test
