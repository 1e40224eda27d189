// A PLY's vertex count is checked against the file before Open3D resizes the
// cloud to it: "element vertex 2000000000" in a tiny file used to cost 48 GB.

#include <filesystem>
#include <fstream>
#include <random>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "boicp/io/point_cloud_io.hpp"

namespace boicp {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

const char kVertexProperties[] = "property float x\nproperty float y\nproperty float z\n";

// Loads `bytes` as a PLY; returns the InputError message or "" when it loaded.
std::string LoadError(const std::string& bytes, size_t* points = nullptr) {
  const fs::path path =
      fs::path(::testing::TempDir()) / ("boicp_ply_" + std::to_string(std::random_device()()));
  std::ofstream(path, std::ios::binary) << bytes;
  LoadOptions options;
  options.format = CloudFormat::kPly;
  std::string message;
  try {
    const LoadedCloud cloud = LoadPointCloud(path.string(), options);
    if (points != nullptr) *points = cloud.points.size();
  } catch (const InputError& e) {
    message = e.what();
    EXPECT_THAT(message, HasSubstr(path.string()));
  }
  fs::remove(path);
  return message;
}

TEST(PlyHeaderTest, VertexCountBeyondTheFileIsRefused) {
  EXPECT_THAT(LoadError(std::string("ply\nformat ascii 1.0\nelement vertex 2000000000\n") +
                        kVertexProperties + "end_header\n1 2 3\n"),
              HasSubstr("truncated PLY (2000000000 vertices of at least 6 bytes declared, 6 "
                        "data bytes)"));
}

// Open3D sizes points, normals and colours (72 bytes) by the vertex count, so
// each vertex must take its properties' bytes in the file: a binary vertex of
// three floats 12, an ascii one 6.
TEST(PlyHeaderTest, VerticesMustFillTheirPropertiesBytes) {
  const std::string binary = std::string("ply\nformat binary_little_endian 1.0\nelement vertex ");
  const std::string floats = std::string(kVertexProperties) + "end_header\n";
  EXPECT_THAT(LoadError(binary + "1000\n" + floats + std::string(11999, '\0')),
              HasSubstr("1000 vertices of at least 12 bytes declared, 11999 data bytes"));
  size_t points = 0;
  EXPECT_EQ(LoadError(binary + "1000\n" + floats + std::string(12000, '\0'), &points), "");
  EXPECT_EQ(points, 1000u);
  // A face list counts its count byte only; doubles count 8.
  EXPECT_THAT(
      LoadError(binary + "10\nproperty double x\nproperty double y\nproperty double z\n" +
                "property list uchar int vertex_indices\nend_header\n" + std::string(249, '\0')),
      HasSubstr("10 vertices of at least 25 bytes declared, 249 data bytes"));
  EXPECT_THAT(LoadError(std::string("ply\nformat ascii 1.0\nelement vertex 3\n") + floats +
                        "1 2 3\n4 5 6\n"),
              HasSubstr("3 vertices of at least 6 bytes declared, 12 data bytes"));
}

TEST(PlyHeaderTest, ElementSplitAcrossLinesIsRefused) {
  // RPly reads words, so it would take "vertex 2000000000" from the next line.
  EXPECT_THAT(LoadError(std::string("ply\nformat ascii 1.0\nelement\nvertex 2000000000\n") +
                        kVertexProperties + "end_header\n1 2 3\n"),
              HasSubstr("line 3 is not a format, comment, element, property or end_header"));
}

TEST(PlyHeaderTest, BarePropertyLineIsAnErrorNotACrash) {
  // Found by fuzz_ply: RPly and Open3D read out of bounds (SEGV) on this file.
  EXPECT_THAT(LoadError("ply\nformat ascii 1.0\ncomment seed\nelement vertex 1\n"
                        "property float x\nproperty\nend_header\n1.0 2.0 .0 1 2\n"),
              HasSubstr("line 6 is not a format"));
}

TEST(PlyHeaderTest, MissingEndHeaderIsRefused) {
  EXPECT_THAT(
      LoadError(std::string("ply\nformat ascii 1.0\nelement vertex 1\n") + kVertexProperties),
      HasSubstr("no end_header"));
}

TEST(PlyHeaderTest, CommentCutOffByTheEndOfFileIsAnErrorNotACrash) {
  // Found by fuzz_ply: RPly called memmove with size -1 on this 35-byte file.
  EXPECT_THAT(LoadError("ply\nformat ascii\n 1.0\ncomment"), HasSubstr("line 2 is not 'format"));
  EXPECT_THAT(LoadError("ply\nformat ascii 1.0\ncomment"), HasSubstr("no end_header"));
}

TEST(PlyHeaderTest, CommentsMentioningElementsAreIgnored) {
  size_t points = 0;
  EXPECT_EQ(LoadError(std::string("ply\nformat ascii 1.0\ncomment element vertex 999999999\n"
                                  "element vertex 1\n") +
                          kVertexProperties + "end_header\n1 2 3\n",
                      &points),
            "");
  EXPECT_EQ(points, 1u);
}

}  // namespace
}  // namespace boicp
