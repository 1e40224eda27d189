// Point-cloud loading: every format on fixtures written at test time, every
// malformed-input error, and (when ../shared/data is present) the real data.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <open3d/geometry/Image.h>
#include <open3d/geometry/PointCloud.h>
#include <open3d/io/ImageIO.h>
#include <open3d/io/PointCloudIO.h>

#include "../support/input_error.hpp"
#include "boicp/io/point_cloud_io.hpp"

#ifndef BOICP_SHARED_DATA_DIR
#define BOICP_SHARED_DATA_DIR ""
#endif

namespace boicp {
namespace {
using boicp::test::InputErrorMessage;

namespace fs = std::filesystem;
using ::testing::HasSubstr;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

void ExpectPointNear(const Point& actual, const Point& expected, double tolerance = 1e-12) {
  EXPECT_NEAR(actual.x(), expected.x(), tolerance);
  EXPECT_NEAR(actual.y(), expected.y(), tolerance);
  EXPECT_NEAR(actual.z(), expected.z(), tolerance);
}

void AppendLittleEndianFloat(float value, std::string* bytes) {
  uint32_t bits = 0;
  std::memcpy(&bits, &value, sizeof(bits));
  for (int shift = 0; shift < 32; shift += 8) {
    bytes->push_back(static_cast<char>((bits >> shift) & 0xFFu));
  }
}

// Every test gets a fresh directory of its own under the gtest temp dir.
class PointCloudIoTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    std::random_device random;
    dir_ = fs::path(::testing::TempDir()) /
           ("boicp_io_" + std::string(info->name()) + "_" + std::to_string(random()));
    fs::create_directories(dir_);
  }
  void TearDown() override {
    std::error_code ignored;
    fs::remove_all(dir_, ignored);
  }

  std::string PathOf(const std::string& name) const { return (dir_ / name).string(); }

  std::string WriteFile(const std::string& name, const std::string& bytes) const {
    const std::string path = PathOf(name);
    std::ofstream(path, std::ios::binary) << bytes;
    return path;
  }

  std::string WriteKitti(const std::string& name, const std::vector<Eigen::Vector4f>& rows) const {
    std::string bytes;
    for (const Eigen::Vector4f& row : rows) {
      for (int i = 0; i < 4; ++i) AppendLittleEndianFloat(row[i], &bytes);
    }
    return WriteFile(name, bytes);
  }

  // A 16-bit single-channel PNG; pixels[v][u] is the raw value at row v, column u.
  std::string WriteDepthPng(const std::string& name,
                            const std::vector<std::vector<uint16_t>>& pixels) const {
    open3d::geometry::Image image;
    image.Prepare(static_cast<int>(pixels[0].size()), static_cast<int>(pixels.size()), 1, 2);
    for (size_t v = 0; v < pixels.size(); ++v) {
      for (size_t u = 0; u < pixels[v].size(); ++u) {
        *image.PointerAt<uint16_t>(static_cast<int>(u), static_cast<int>(v)) = pixels[v][u];
      }
    }
    const std::string path = PathOf(name);
    EXPECT_TRUE(open3d::io::WriteImage(path, image)) << path;
    return path;
  }

  std::string WritePng(const std::string& name, int channels, int bytes_per_channel) const {
    open3d::geometry::Image image;
    image.Prepare(4, 3, channels, bytes_per_channel);
    std::fill(image.data_.begin(), image.data_.end(), uint8_t{7});
    const std::string path = PathOf(name);
    EXPECT_TRUE(open3d::io::WriteImage(path, image)) << path;
    return path;
  }

  static LoadOptions DepthOptionsFor(double fx, double fy, double cx, double cy, double scale) {
    LoadOptions options;
    options.depth.intrinsics = Intrinsics{fx, fy, cx, cy};
    options.depth.depth_scale = scale;
    return options;
  }

  fs::path dir_;
};

// ---------------------------------------------------------------- formats

TEST_F(PointCloudIoTest, ParseCloudFormatAcceptsDocumentedNamesAndRoundTrips) {
  EXPECT_EQ(ParseCloudFormat("auto"), CloudFormat::kAuto);
  EXPECT_EQ(ParseCloudFormat("kitti"), CloudFormat::kKittiBin);
  EXPECT_EQ(ParseCloudFormat("bin"), CloudFormat::kKittiBin);
  EXPECT_EQ(ParseCloudFormat("pcd"), CloudFormat::kPcd);
  EXPECT_EQ(ParseCloudFormat("ply"), CloudFormat::kPly);
  EXPECT_EQ(ParseCloudFormat("xyz"), CloudFormat::kXyz);
  EXPECT_EQ(ParseCloudFormat("depth"), CloudFormat::kDepthPng);
  EXPECT_EQ(ParseCloudFormat("png"), CloudFormat::kDepthPng);
  for (CloudFormat format : {CloudFormat::kAuto, CloudFormat::kKittiBin, CloudFormat::kPcd,
                             CloudFormat::kPly, CloudFormat::kXyz, CloudFormat::kDepthPng}) {
    EXPECT_EQ(ParseCloudFormat(CloudFormatName(format)), format) << CloudFormatName(format);
  }
  EXPECT_THAT(InputErrorMessage([] { ParseCloudFormat("las"); }), HasSubstr("'las'"));
}

TEST_F(PointCloudIoTest, DetectCloudFormatFromExtensionInAnyCase) {
  EXPECT_EQ(DetectCloudFormat("a/000000.bin"), CloudFormat::kKittiBin);
  EXPECT_EQ(DetectCloudFormat("scan.PCD"), CloudFormat::kPcd);
  EXPECT_EQ(DetectCloudFormat("bun000.Ply"), CloudFormat::kPly);
  EXPECT_EQ(DetectCloudFormat("cloud.xyz"), CloudFormat::kXyz);
  EXPECT_EQ(DetectCloudFormat("cloud.txt"), CloudFormat::kXyz);
  EXPECT_EQ(DetectCloudFormat("frame-000000.depth.png"), CloudFormat::kDepthPng);
}

TEST_F(PointCloudIoTest, UnknownExtensionNamesFileAndListsSupportedOnes) {
  const std::string path = WriteFile("cloud.las", "1 2 3\n");
  const std::string message = InputErrorMessage([&] { LoadPointCloud(path); });
  EXPECT_THAT(message, HasSubstr(path));
  EXPECT_THAT(message, HasSubstr(".bin .pcd .ply .xyz .txt .png"));
  EXPECT_THAT(InputErrorMessage([] { DetectCloudFormat("noextension"); }),
              HasSubstr("no extension"));
}

TEST_F(PointCloudIoTest, ExplicitFormatOverridesExtension) {
  const std::string path = WriteFile("cloud.dat", "1 2 3\n");
  LoadOptions options;
  options.format = CloudFormat::kXyz;
  const LoadedCloud cloud = LoadPointCloud(path, options);
  ASSERT_EQ(cloud.points.size(), 1u);
  EXPECT_EQ(cloud.format, CloudFormat::kXyz);
  ExpectPointNear(cloud.points[0], Point(1, 2, 3));
}

TEST_F(PointCloudIoTest, MissingFileAndDirectoryGiveClearErrors) {
  const std::string missing = PathOf("missing.ply");
  EXPECT_THAT(InputErrorMessage([&] { LoadPointCloud(missing); }),
              HasSubstr(missing + ": no such file"));
  fs::create_directories(dir_ / "scan.pcd");
  const std::string directory = PathOf("scan.pcd");
  EXPECT_THAT(InputErrorMessage([&] { LoadPointCloud(directory); }),
              HasSubstr(directory + ": is a directory"));
}

// ---------------------------------------------------------------- KITTI

TEST_F(PointCloudIoTest, KittiBinLoadsKnownPointsAndIgnoresReflectance) {
  const std::string path = WriteKitti(
      "000000.bin",
      {{1.5f, -2.25f, 3.0f, 0.5f}, {-10.125f, 0.0f, 1e-3f, 0.0f}, {40.0f, 20.5f, -1.75f, 1.0f}});
  const LoadedCloud cloud = LoadPointCloud(path);
  EXPECT_EQ(cloud.format, CloudFormat::kKittiBin);
  EXPECT_EQ(cloud.dropped_nonfinite, 0u);
  ASSERT_EQ(cloud.points.size(), 3u);
  ExpectPointNear(cloud.points[0], Point(1.5, -2.25, 3.0));
  ExpectPointNear(cloud.points[1], Point(-10.125, 0.0, static_cast<double>(1e-3f)));
  ExpectPointNear(cloud.points[2], Point(40.0, 20.5, -1.75));
}

TEST_F(PointCloudIoTest, KittiBinDropsAndCountsNonFinitePoints) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float inf = std::numeric_limits<float>::infinity();
  const std::string path =
      WriteKitti("nan.bin", {{nan, 0, 0, 0}, {1, 2, 3, 0}, {0, -inf, 0, 0}, {4, 5, 6, nan}});
  const LoadedCloud cloud = LoadPointCloud(path);
  EXPECT_EQ(cloud.dropped_nonfinite, 2u);
  ASSERT_EQ(cloud.points.size(), 2u);
  ExpectPointNear(cloud.points[0], Point(1, 2, 3));
  ExpectPointNear(cloud.points[1], Point(4, 5, 6));
}

TEST_F(PointCloudIoTest, TruncatedKittiBinNamesFileAndSize) {
  std::string bytes;
  for (int i = 0; i < 5; ++i) AppendLittleEndianFloat(1.0f, &bytes);
  const std::string path = WriteFile("truncated.bin", bytes);
  EXPECT_THAT(InputErrorMessage([&] { LoadPointCloud(path); }),
              HasSubstr(path + ": truncated KITTI .bin (20 bytes is not a multiple of 16)"));
}

TEST_F(PointCloudIoTest, EmptyKittiBinIsAnError) {
  const std::string path = WriteFile("empty.bin", "");
  EXPECT_THAT(InputErrorMessage([&] { LoadPointCloud(path); }), HasSubstr(path + ": empty"));
}

TEST_F(PointCloudIoTest, AllNonFinitePointsLeaveNoCloud) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const std::string path = WriteKitti("allnan.bin", {{nan, nan, nan, 0}});
  EXPECT_THAT(InputErrorMessage([&] { LoadPointCloud(path); }),
              HasSubstr(path + ": no finite points"));
}

// ---------------------------------------------------------------- PCD

TEST_F(PointCloudIoTest, AsciiPcdWithExtraFieldLoadsAndDropsNaN) {
  const std::string path = WriteFile("scan.pcd",
                                     "# .PCD v0.7 - Point Cloud Data file format\n"
                                     "VERSION 0.7\nFIELDS x y z intensity\nSIZE 4 4 4 4\n"
                                     "TYPE F F F F\nCOUNT 1 1 1 1\nWIDTH 3\nHEIGHT 1\n"
                                     "VIEWPOINT 0 0 0 1 0 0 0\nPOINTS 3\nDATA ascii\n"
                                     "0.5 -1.25 2 7\nnan nan nan 0\n-3 4.75 0.125 1\n");
  const LoadedCloud cloud = LoadPointCloud(path);
  EXPECT_EQ(cloud.format, CloudFormat::kPcd);
  EXPECT_EQ(cloud.dropped_nonfinite, 1u);
  ASSERT_EQ(cloud.points.size(), 2u);
  ExpectPointNear(cloud.points[0], Point(0.5, -1.25, 2));
  ExpectPointNear(cloud.points[1], Point(-3, 4.75, 0.125));
}

TEST_F(PointCloudIoTest, BinaryPcdWrittenByOpen3dRoundTrips) {
  // Open3D writes PCD coordinates as float32, so these are exact in float.
  const Points written = {Point(0.125, -0.75, 3.5), Point(-5.5, 6.25, -7.0),
                          Point(1024, -0.0009765625, 0)};
  open3d::geometry::PointCloud source(written);
  const std::string path = PathOf("binary.pcd");
  ASSERT_TRUE(open3d::io::WritePointCloud(path, source));
  const LoadedCloud cloud = LoadPointCloud(path);
  ASSERT_EQ(cloud.points.size(), written.size());
  for (size_t i = 0; i < written.size(); ++i) EXPECT_EQ(cloud.points[i], written[i]) << i;
}

TEST_F(PointCloudIoTest, GarbagePcdNamesFile) {
  const std::string path = WriteFile("garbage.pcd", "this is not a point cloud\n");
  EXPECT_THAT(InputErrorMessage([&] { LoadPointCloud(path); }), HasSubstr(path));
}

// ---------------------------------------------------------------- PLY

TEST_F(PointCloudIoTest, AsciiPlyWithRangeGridElementAndCrlfLoadsVerticesOnly) {
  // Shaped like the Stanford bunny scans: CRLF lines, obj_info, and a
  // range_grid list element after the vertices.
  const std::string path = WriteFile("bun.ply",
                                     "ply\r\nformat ascii 1.0\r\nobj_info num_cols 2\r\n"
                                     "element vertex 3\r\nproperty float x\r\n"
                                     "property float y\r\nproperty float z\r\n"
                                     "element range_grid 4\r\n"
                                     "property list uchar int vertex_indices\r\nend_header\r\n"
                                     "-0.06325 0.0359793 0.0420873 \r\n"
                                     "nan 0 0 \r\n"
                                     "0.5 -0.25 1 \r\n"
                                     "1 0\r\n0\r\n1 2\r\n0\r\n");
  const LoadedCloud cloud = LoadPointCloud(path);
  EXPECT_EQ(cloud.format, CloudFormat::kPly);
  EXPECT_EQ(cloud.dropped_nonfinite, 1u);
  ASSERT_EQ(cloud.points.size(), 2u);
  ExpectPointNear(cloud.points[0], Point(-0.06325, 0.0359793, 0.0420873), 1e-7);
  ExpectPointNear(cloud.points[1], Point(0.5, -0.25, 1));
}

TEST_F(PointCloudIoTest, BinaryLittleEndianPlyLoads) {
  std::string bytes =
      "ply\nformat binary_little_endian 1.0\nelement vertex 2\n"
      "property float x\nproperty float y\nproperty float z\nend_header\n";
  for (float value : {1.5f, -2.0f, 0.25f, -8.0f, 16.5f, 3.0f}) {
    AppendLittleEndianFloat(value, &bytes);
  }
  const std::string path = WriteFile("binary.ply", bytes);
  const LoadedCloud cloud = LoadPointCloud(path);
  ASSERT_EQ(cloud.points.size(), 2u);
  ExpectPointNear(cloud.points[0], Point(1.5, -2.0, 0.25));
  ExpectPointNear(cloud.points[1], Point(-8.0, 16.5, 3.0));
}

TEST_F(PointCloudIoTest, BadPlyHeaderNamesFile) {
  for (const std::string& content :
       {std::string("garbage\n"), std::string("ply\nformat nonsense\n"), std::string("")}) {
    const std::string path = WriteFile("bad.ply", content);
    EXPECT_THAT(InputErrorMessage([&] { LoadPointCloud(path); }), HasSubstr(path))
        << "content: " << content;
  }
}

TEST_F(PointCloudIoTest, TruncatedPlyIsAnErrorNotGarbagePoints) {
  // Open3D returns false here but leaves uninitialised vertices in the cloud.
  const std::string path = WriteFile("short.ply",
                                     "ply\nformat ascii 1.0\nelement vertex 3\n"
                                     "property float x\nproperty float y\nproperty float z\n"
                                     "end_header\n1 2 3\n4 5\n");
  EXPECT_THAT(InputErrorMessage([&] { LoadPointCloud(path); }), HasSubstr(path));
}

TEST_F(PointCloudIoTest, PlyWithoutVerticesIsAnError) {
  const std::string path = WriteFile("faces.ply",
                                     "ply\nformat ascii 1.0\nelement face 0\n"
                                     "property list uchar int vertex_indices\nend_header\n");
  EXPECT_THAT(InputErrorMessage([&] { LoadPointCloud(path); }), HasSubstr(path));
}

// ---------------------------------------------------------------- XYZ

TEST_F(PointCloudIoTest, XyzAcceptsCommentsSeparatorsExtraColumnsAndCrlf) {
  const std::string path = WriteFile("cloud.xyz",
                                     "# x y z intensity\n"
                                     "\n"
                                     "1 2 3\n"
                                     "  -4.5\t5e-1\t+6   0.9 label\r\n"
                                     "7,8,9,255,0,0\n"
                                     "nan 1 1\n"
                                     "1 inf 1\n"
                                     "   \n"
                                     "-1.25, 0.0 ,1e2\n");
  const LoadedCloud cloud = LoadPointCloud(path);
  EXPECT_EQ(cloud.format, CloudFormat::kXyz);
  EXPECT_EQ(cloud.dropped_nonfinite, 2u);
  ASSERT_EQ(cloud.points.size(), 4u);
  ExpectPointNear(cloud.points[0], Point(1, 2, 3));
  ExpectPointNear(cloud.points[1], Point(-4.5, 0.5, 6));
  ExpectPointNear(cloud.points[2], Point(7, 8, 9));
  ExpectPointNear(cloud.points[3], Point(-1.25, 0, 100));
}

TEST_F(PointCloudIoTest, XyzLineWithTooFewNumbersNamesFileAndLine) {
  const std::string path = WriteFile("short.xyz", "# header\n1 2 3\n4 5\n");
  EXPECT_THAT(InputErrorMessage([&] { LoadPointCloud(path); }),
              HasSubstr(path + ":3: expected at least 3 numbers"));
}

TEST_F(PointCloudIoTest, XyzNonNumericFieldNamesFileAndLine) {
  const std::string path = WriteFile("words.txt", "1 2 3\n1 2 three\n");
  EXPECT_THAT(InputErrorMessage([&] { LoadPointCloud(path); }),
              HasSubstr(path + ":2: expected at least 3 numbers"));
  const std::string partial = WriteFile("partial.xyz", "1 2 3abc\n");
  EXPECT_THAT(InputErrorMessage([&] { LoadPointCloud(partial); }),
              HasSubstr(partial + ":1: expected at least 3 numbers"));
}

TEST_F(PointCloudIoTest, XyzWithOnlyCommentsHasNoFinitePoints) {
  const std::string path = WriteFile("empty.xyz", "# nothing here\n\n");
  EXPECT_THAT(InputErrorMessage([&] { LoadPointCloud(path); }),
              HasSubstr(path + ": no finite points"));
}

TEST_F(PointCloudIoTest, WriteXyzThenLoadRoundTripsExactly) {
  const Points written = {Point(0.1, -0.2, 1.0 / 3.0), Point(1e-300, -123456.789, 0),
                          Point(3.141592653589793, -2.718281828459045, 1e17)};
  const std::string path = PathOf("written.xyz");
  WriteXyz(path, written);
  const LoadedCloud cloud = LoadPointCloud(path);
  ASSERT_EQ(cloud.points.size(), written.size());
  for (size_t i = 0; i < written.size(); ++i) EXPECT_EQ(cloud.points[i], written[i]) << i;
}

TEST_F(PointCloudIoTest, WriteXyzIntoMissingDirectoryThrows) {
  const std::string path = PathOf("no/such/dir/out.xyz");
  EXPECT_THAT(InputErrorMessage([&] { WriteXyz(path, {Point(1, 2, 3)}); }), HasSubstr(path));
}

// ---------------------------------------------------------------- depth PNG

TEST_F(PointCloudIoTest, DepthPngBackProjectsPixelsByPinholeFormula) {
  // 3 rows x 4 columns; 0 and 65535 are the default invalid values.
  const std::string path =
      WriteDepthPng("frame.depth.png", {{0, 1000, 65535, 0}, {0, 0, 1500, 0}, {0, 0, 0, 2500}});
  const LoadedCloud cloud = LoadPointCloud(path, DepthOptionsFor(500, 400, 1.5, 0.5, 1000));
  EXPECT_EQ(cloud.format, CloudFormat::kDepthPng);
  EXPECT_EQ(cloud.dropped_nonfinite, 0u);
  ASSERT_EQ(cloud.points.size(), 3u);  // row-major pixel order
  // (u=1, v=0, d=1000): z = 1, x = (1 - 1.5) * 1 / 500, y = (0 - 0.5) * 1 / 400.
  ExpectPointNear(cloud.points[0], Point(-0.001, -0.00125, 1.0));
  // (u=2, v=1, d=1500): z = 1.5, x = 0.5 * 1.5 / 500, y = 0.5 * 1.5 / 400.
  ExpectPointNear(cloud.points[1], Point(0.0015, 0.001875, 1.5));
  // (u=3, v=2, d=2500): z = 2.5, x = 1.5 * 2.5 / 500, y = 1.5 * 2.5 / 400.
  ExpectPointNear(cloud.points[2], Point(0.0075, 0.009375, 2.5));
}

TEST_F(PointCloudIoTest, DepthPngHonoursCustomInvalidValuesAndScale) {
  const std::string path = WriteDepthPng("custom.png", {{0, 5000, 9999}});
  LoadOptions options = DepthOptionsFor(1, 1, 0, 0, 5000);
  options.depth.invalid_values = {9999};
  const LoadedCloud cloud = LoadPointCloud(path, options);
  ASSERT_EQ(cloud.points.size(), 2u);
  ExpectPointNear(cloud.points[0], Point(0, 0, 0));  // raw 0 is valid when not listed
  ExpectPointNear(cloud.points[1], Point(1, 0, 1));
}

TEST_F(PointCloudIoTest, DepthPngWithExplicitFormatAndOtherExtensionLoads) {
  const std::string png = WriteDepthPng("frame.png", {{1000}});
  const std::string renamed = PathOf("frame.depth");
  fs::rename(png, renamed);
  LoadOptions options = DepthOptionsFor(1, 1, 0, 0, 1000);
  options.format = CloudFormat::kDepthPng;
  EXPECT_EQ(LoadPointCloud(renamed, options).points.size(), 1u);
}

TEST_F(PointCloudIoTest, EightBitPngIsRejectedWithItsLayout) {
  const std::string path = WritePng("gray8.png", 1, 1);
  EXPECT_THAT(InputErrorMessage([&] { LoadPointCloud(path, DepthOptionsFor(1, 1, 0, 0, 1)); }),
              HasSubstr(path + ": depth PNG must be 16-bit single-channel (got 1 channels, "
                               "1 bytes per channel)"));
}

TEST_F(PointCloudIoTest, ThreeChannelPngIsRejectedWithItsLayout) {
  const std::string rgb8 = WritePng("rgb8.png", 3, 1);
  EXPECT_THAT(InputErrorMessage([&] { LoadPointCloud(rgb8, DepthOptionsFor(1, 1, 0, 0, 1)); }),
              HasSubstr(rgb8 + ": depth PNG must be 16-bit single-channel (got 3 channels, "
                               "1 bytes per channel)"));
  const std::string rgb16 = WritePng("rgb16.png", 3, 2);
  EXPECT_THAT(InputErrorMessage([&] { LoadPointCloud(rgb16, DepthOptionsFor(1, 1, 0, 0, 1)); }),
              HasSubstr(rgb16 + ": depth PNG must be 16-bit single-channel (got 3 channels, "
                                "2 bytes per channel)"));
}

TEST_F(PointCloudIoTest, DepthPngWithoutIntrinsicsOrScaleNamesTheFlag) {
  const std::string path = WriteDepthPng("frame.png", {{1000}});
  LoadOptions no_intrinsics;
  no_intrinsics.depth.depth_scale = 1000;
  const std::string intrinsics_message =
      InputErrorMessage([&] { LoadPointCloud(path, no_intrinsics); });
  EXPECT_THAT(intrinsics_message, HasSubstr(path));
  EXPECT_THAT(intrinsics_message, HasSubstr("--intrinsics/--intrinsics-file"));

  LoadOptions no_scale;
  no_scale.depth.intrinsics = Intrinsics{1, 1, 0, 0};
  const std::string scale_message = InputErrorMessage([&] { LoadPointCloud(path, no_scale); });
  EXPECT_THAT(scale_message, HasSubstr(path));
  EXPECT_THAT(scale_message, HasSubstr("--depth-scale"));
}

TEST_F(PointCloudIoTest, CorruptPngNamesFile) {
  const std::string path = WriteFile("corrupt.png", "\x89PNG\r\n\x1a\nnot really");
  EXPECT_THAT(InputErrorMessage([&] { LoadPointCloud(path, DepthOptionsFor(1, 1, 0, 0, 1)); }),
              HasSubstr(path));
}

// ---------------------------------------------------------------- intrinsics

TEST_F(PointCloudIoTest, ParseIntrinsicsReadsFourNumbers) {
  const Intrinsics k = ParseIntrinsics("585,585.5, 320 ,240.25");
  EXPECT_EQ(k.fx, 585.0);
  EXPECT_EQ(k.fy, 585.5);
  EXPECT_EQ(k.cx, 320.0);
  EXPECT_EQ(k.cy, 240.25);
}

TEST_F(PointCloudIoTest, ParseIntrinsicsRejectsMalformedText) {
  for (const char* text : {"585,585,320", "585,585,320,240,1", "a,585,320,240", "0,585,320,240",
                           "585,-1,320,240", "585,585,nan,240", ""}) {
    EXPECT_THAT(InputErrorMessage([&] { ParseIntrinsics(text); }), HasSubstr("intrinsics")) << text;
  }
}

TEST_F(PointCloudIoTest, ReadIntrinsicsFileAcceptsFourNumbersOrCameraMatrix) {
  const Intrinsics four = ReadIntrinsicsFile(WriteFile("four.txt", "525 526 319.5 239.5\n"));
  EXPECT_EQ(four.fx, 525.0);
  EXPECT_EQ(four.fy, 526.0);
  EXPECT_EQ(four.cx, 319.5);
  EXPECT_EQ(four.cy, 239.5);
  // The exact layout of 7-Scenes' camera-intrinsics.txt.
  const Intrinsics k = ReadIntrinsicsFile(
      WriteFile("camera-intrinsics.txt",
                "5.850000000000000000e+02 0.000000000000000000e+00 3.200000000000000000e+02\n"
                "0.000000000000000000e+00 5.860000000000000000e+02 2.400000000000000000e+02\n"
                "0.000000000000000000e+00 0.000000000000000000e+00 1.000000000000000000e+00\n"));
  EXPECT_EQ(k.fx, 585.0);
  EXPECT_EQ(k.fy, 586.0);
  EXPECT_EQ(k.cx, 320.0);
  EXPECT_EQ(k.cy, 240.0);
}

TEST_F(PointCloudIoTest, ReadIntrinsicsFileRejectsOtherShapes) {
  const std::string five = WriteFile("five.txt", "1 2 3 4 5\n");
  EXPECT_THAT(InputErrorMessage([&] { ReadIntrinsicsFile(five); }), HasSubstr(five));
  const std::string skew = WriteFile("skew.txt", "585 1 320\n0 585 240\n0 0 1\n");
  EXPECT_THAT(InputErrorMessage([&] { ReadIntrinsicsFile(skew); }), HasSubstr(skew));
  const std::string words = WriteFile("words.txt", "fx fy cx cy\n");
  EXPECT_THAT(InputErrorMessage([&] { ReadIntrinsicsFile(words); }), HasSubstr(words + ":1:"));
  const std::string missing = PathOf("missing.txt");
  EXPECT_THAT(InputErrorMessage([&] { ReadIntrinsicsFile(missing); }),
              HasSubstr(missing + ": no such file"));
}

// ---------------------------------------------------------------- transforms

TEST_F(PointCloudIoTest, ReadTransformFileAcceptsThreeByFourAndFourByFour) {
  Transform expected = Transform::Identity();
  expected.topLeftCorner<3, 3>() =
      Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  expected.topRightCorner<3, 1>() = Eigen::Vector3d(1.5, -2, 0.25);
  std::ostringstream rows;
  rows.precision(17);
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 4; ++c) rows << expected(r, c) << (c < 3 ? " " : "\n");
  }
  const Transform from12 = ReadTransformFile(WriteFile("t12.txt", rows.str()));
  EXPECT_TRUE(from12.isApprox(expected, 1e-15)) << from12;
  const Transform from16 =
      ReadTransformFile(WriteFile("t16.txt", "# T_target_source\n" + rows.str() + "0 0 0 1\n"));
  EXPECT_TRUE(from16.isApprox(expected, 1e-15)) << from16;
}

TEST_F(PointCloudIoTest, ReadTransformFileRejectsNonRigidOrMisshapenInput) {
  const std::string scaled = WriteFile("scaled.txt", "2 0 0 0\n0 1 0 0\n0 0 1 0\n");
  EXPECT_THAT(InputErrorMessage([&] { ReadTransformFile(scaled); }),
              HasSubstr(scaled + ": rotation part is not orthonormal"));
  const std::string mirror = WriteFile("mirror.txt", "-1 0 0 0\n0 1 0 0\n0 0 1 0\n");
  EXPECT_THAT(InputErrorMessage([&] { ReadTransformFile(mirror); }), HasSubstr(mirror));
  const std::string eleven = WriteFile("eleven.txt", "1 0 0 0\n0 1 0 0\n0 0 1\n");
  EXPECT_THAT(InputErrorMessage([&] { ReadTransformFile(eleven); }),
              HasSubstr(eleven + ": expected 12 (3x4) or 16 (4x4) numbers"));
  const std::string bottom = WriteFile("bottom.txt", "1 0 0 0\n0 1 0 0\n0 0 1 0\n0 0 1 1\n");
  EXPECT_THAT(InputErrorMessage([&] { ReadTransformFile(bottom); }),
              HasSubstr(bottom + ": last row"));
  const std::string words = WriteFile("words.txt", "1 0 0 0\n0 1 zero 0\n0 0 1 0\n");
  EXPECT_THAT(InputErrorMessage([&] { ReadTransformFile(words); }),
              HasSubstr(words + ":2: 'zero' is not a number"));
}

TEST_F(PointCloudIoTest, ReadTransformFileToleratesSmallRoundingInRotation) {
  const Transform T =
      ReadTransformFile(WriteFile("rounded.txt", "1.0004 0 0 0\n0 1 0 0\n0 0 1 0\n"));
  EXPECT_DOUBLE_EQ(T(0, 0), 1.0004);
}

// ---------------------------------------------------------------- real data

// Real KITTI / 7-Scenes / bunny files beside the project; never copied into it.
class RealDataIoTest : public ::testing::Test {
 protected:
  void SetUp() override {
    root_ = fs::path(BOICP_SHARED_DATA_DIR);
    if (root_.empty() || !fs::is_directory(root_)) {
      GTEST_SKIP() << "real data folder '" << root_.string()
                   << "' (BOICP_SHARED_DATA_DIR, ../shared/data) is absent";
    }
  }

  std::string Require(const std::string& relative) {
    const fs::path path = root_ / relative;
    if (!fs::is_regular_file(path)) {
      ADD_FAILURE() << "real data folder exists but lacks " << path;
    }
    return path.string();
  }

  fs::path root_;
};

TEST_F(RealDataIoTest, LoadsKittiVelodyneScan) {
  const std::string path = Require("kitti00/velodyne/000000.bin");
  const LoadedCloud cloud = LoadPointCloud(path);
  EXPECT_EQ(cloud.points.size() + cloud.dropped_nonfinite, fs::file_size(path) / 16);
  EXPECT_GT(cloud.points.size(), 100000u);
  double max_range = 0;
  for (const Point& p : cloud.points) max_range = std::max(max_range, p.norm());
  // An HDL-64E sees up to about 120 m; millions of metres would mean misread bytes.
  EXPECT_GT(max_range, 20.0);
  EXPECT_LT(max_range, 200.0);
}

TEST_F(RealDataIoTest, LoadsBunnyPlyWithRangeGrid) {
  const std::string path = Require("bunny/bun000.ply");
  std::ifstream in(path);
  std::string header_line;
  size_t declared = 0;
  const std::regex vertex_line(R"(element vertex (\d+)\r?)");
  std::smatch match;
  while (std::getline(in, header_line) && header_line.rfind("end_header", 0) != 0) {
    if (std::regex_match(header_line, match, vertex_line)) declared = std::stoul(match[1]);
  }
  ASSERT_GT(declared, 0u) << "no 'element vertex' line in " << path;
  const LoadedCloud cloud = LoadPointCloud(path);
  EXPECT_EQ(cloud.points.size() + cloud.dropped_nonfinite, declared);
  ExpectPointNear(cloud.points.front(), Point(-0.06325, 0.0359793, 0.0420873), 1e-7);
  for (const Point& p : cloud.points) ASSERT_LT(p.norm(), 0.5) << "bunny is ~0.15 m wide";
}

TEST_F(RealDataIoTest, LoadsSevenScenesDepthPng) {
  const std::string path = Require("7scenes_redkitchen/depth/frame-000000.depth.png");
  LoadOptions options;
  options.depth.intrinsics =
      ReadIntrinsicsFile(Require("7scenes_redkitchen/camera-intrinsics.txt"));
  EXPECT_EQ(options.depth.intrinsics->fx, 585.0);
  EXPECT_EQ(options.depth.intrinsics->cy, 240.0);
  options.depth.depth_scale = 1000.0;
  const LoadedCloud cloud = LoadPointCloud(path, options);
  EXPECT_GT(cloud.points.size(), 200000u);  // 640 x 480 minus ~10 % invalid
  EXPECT_LE(cloud.points.size(), 640u * 480u);
  for (const Point& p : cloud.points) {
    ASSERT_GE(p.z(), 0.8) << "7-Scenes valid depth starts at 0.80 m";
    ASSERT_LE(p.z(), 4.0) << "7-Scenes valid depth ends at 3.98 m";
  }
  // Pixel (u=100, v=200) holds raw 2384 (checked with an independent decoder).
  const double z = 2.384;
  const Point expected((100 - 320) * z / 585, (200 - 240) * z / 585, z);
  const bool found = std::any_of(cloud.points.begin(), cloud.points.end(),
                                 [&](const Point& p) { return (p - expected).norm() < 1e-9; });
  EXPECT_TRUE(found) << "no point back-projected from pixel (100, 200)";
}

}  // namespace
}  // namespace boicp
