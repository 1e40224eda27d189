// Scans exported far from their frame's origin (a site frame, or UTM
// coordinates) register as they do at the origin: the engine works on
// centred clouds, so neither the voxel grids' precision nor the ICP steps
// depend on where the frame's origin is. Each dataset's first pair is moved
// 10 km and 5.4e6 m, written as a double-precision PLY and read back, and
// registered with no flags; the answer, carried back to the scans' own
// origin, must be the one at the origin within a tenth of the dataset's
// success thresholds, and right.

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>

#include "../support/files_and_processes.hpp"
#include "boicp/io/point_cloud_io.hpp"
#include "boicp/registration/bo_icp.hpp"
#include "evaluation.hpp"
#include "shared_data.hpp"

namespace boicp {
namespace {

struct OriginCase {
  std::string name;  // folder under ../shared/data
  bool depth_images;
  double max_rotation_deg, max_translation_m;  // success, as the bench judges the dataset
};

std::ostream& operator<<(std::ostream& os, const OriginCase& c) { return os << c.name; }

void WriteDoublePly(const std::filesystem::path& path, const Points& points) {
  std::ofstream out(path);
  out << "ply\nformat ascii 1.0\nelement vertex " << points.size()
      << "\nproperty double x\nproperty double y\nproperty double z\nend_header\n";
  out.precision(17);
  for (const Point& p : points) out << p.x() << ' ' << p.y() << ' ' << p.z() << '\n';
}

Points Moved(const Points& points, const Point& offset) {
  Points moved = points;
  for (Point& p : moved) p += offset;
  return moved;
}

class OriginFree : public ::testing::TestWithParam<OriginCase> {};

TEST_P(OriginFree, ScansFarFromTheOriginRegisterAsAtTheOrigin) {
  const OriginCase& dataset = GetParam();
  const std::filesystem::path folder = SharedDataFolder(dataset.name);
  if (const std::string missing = MissingSharedData(folder); !missing.empty())
    GTEST_SKIP() << missing;
  const ReferencePair pair = ReadPairsCsv((folder / "pairs.csv").string()).front();
  const LoadOptions load = SharedDataLoadOptions(folder, dataset.depth_images);
  const Points source = LoadPointCloud(pair.source, load).points;
  const Points target = LoadPointCloud(pair.target, load).points;
  BoIcpConfig config = PresetConfig("C");
  config.threads = 2;
  const RegistrationResult at_origin = RegisterPair(source, target, config);
  ASSERT_LT(RotationErrorDeg(at_origin.transform, pair.T_target_source), dataset.max_rotation_deg);
  ASSERT_LT(TranslationErrorM(at_origin.transform, pair.T_target_source),
            dataset.max_translation_m);

  const test::ScratchDir scratch("boicp_origin_free");
  for (const Point& offset : {Point(7000.0, -7000.0, 150.0), Point(452000.0, 5411000.0, 250.0)}) {
    SCOPED_TRACE("moved by " + std::to_string(offset.norm()) + " m");
    WriteDoublePly(scratch.path() / "source.ply", Moved(source, offset));
    WriteDoublePly(scratch.path() / "target.ply", Moved(target, offset));
    const RegistrationResult moved =
        RegisterPair(LoadPointCloud((scratch.path() / "source.ply").string()).points,
                     LoadPointCloud((scratch.path() / "target.ply").string()).points, config);
    // T_target_source of the scans at the origin: move them out, apply, move back.
    Transform to_offset = Transform::Identity();
    to_offset.topRightCorner<3, 1>() = offset;
    const Transform back = to_offset.inverse() * moved.transform * to_offset;
    const double rotation = RotationErrorDeg(back, at_origin.transform);
    const double translation = TranslationErrorM(back, at_origin.transform);
    std::printf(
        "%s moved %.0f m: %.4f deg and %.5f m from the answer at the origin, "
        "confidence %.3f (%.3f at the origin)\n",
        dataset.name.c_str(), offset.norm(), rotation, translation, moved.confidence,
        at_origin.confidence);
    EXPECT_LT(rotation, 0.1 * dataset.max_rotation_deg);
    EXPECT_LT(translation, 0.1 * dataset.max_translation_m);
    EXPECT_FALSE(moved.doubtful);
  }
}

INSTANTIATE_TEST_SUITE_P(SharedData, OriginFree,
                         ::testing::Values(OriginCase{"kitti00", false, 2.0, 0.3},
                                           OriginCase{"7scenes_redkitchen", true, 2.0, 0.05},
                                           OriginCase{"bunny", false, 2.0, 0.005}),
                         [](const ::testing::TestParamInfo<OriginCase>& info) {
                           return TestName(info.param.name);
                         });

}  // namespace
}  // namespace boicp
