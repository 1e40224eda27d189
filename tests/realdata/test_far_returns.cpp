// Automatic settings on real scans with far returns (bench/field_conditions:
// 3 % of returns 15-40 RMS radii out, as through windows or open doors).
// Clean scans set no point aside; with far returns, every added point is set
// aside (but for a few of the nearest) and the settings are the clean
// scan's, within what a different random sample of the measured points
// makes: 3 % for the RMS radius's voxel and box, 5 % for the ray length.

#include <cmath>
#include <filesystem>
#include <set>

#include <gtest/gtest.h>

#include "boicp/io/point_cloud_io.hpp"
#include "boicp/registration/auto_settings.hpp"
#include "evaluation.hpp"
#include "field_conditions.hpp"
#include "shared_data.hpp"

namespace boicp {
namespace {

struct ScanDataset {
  std::string name;  // folder under ../shared/data
  bool depth_images;
};

std::ostream& operator<<(std::ostream& os, const ScanDataset& c) { return os << c.name; }

class FarReturns : public ::testing::TestWithParam<ScanDataset> {};

void ExpectClose(double far, double clean, double tolerance, const std::string& what) {
  EXPECT_NEAR(far, clean, tolerance * clean) << what;
}

TEST_P(FarReturns, AreSetAsideBeforeChoosingSettings) {
  const ScanDataset& dataset = GetParam();
  const std::filesystem::path folder = SharedDataFolder(dataset.name);
  if (const std::string missing = MissingSharedData(folder); !missing.empty())
    GTEST_SKIP() << missing;
  const LoadOptions load = SharedDataLoadOptions(folder, dataset.depth_images);
  std::set<std::string> scans;
  for (const ReferencePair& pair : ReadPairsCsv((folder / "pairs.csv").string())) {
    scans.insert(pair.source);
    scans.insert(pair.target);
  }
  uint64_t seed = 1;
  for (const std::string& scan : scans) {
    SCOPED_TRACE(scan);
    const Points clean = LoadPointCloud(scan, load).points;
    const Points far =
        bench::ApplyFieldCondition(bench::FieldCondition::kFarReturns, clean, clean, seed++).source;
    const CloudStatistics clean_stats = MeasureCloud(clean, 7);
    const CloudStatistics far_stats = MeasureCloud(far, 7);
    EXPECT_EQ(clean_stats.far_returns, 0u);
    // The nearest added returns may fall inside the gate; no scan point may fall outside.
    const size_t added = far.size() - clean.size();
    EXPECT_LE(far_stats.far_returns, added);
    EXPECT_GE(static_cast<double>(far_stats.far_returns), 0.99 * static_cast<double>(added));

    const ChosenSettings a = ChooseSettings({clean_stats}, std::nullopt);
    const ChosenSettings b = ChooseSettings({far_stats}, std::nullopt);
    EXPECT_EQ(a.sensor, b.sensor);
    ExpectClose(b.voxel, a.voxel, 0.03, "voxel");
    for (int axis = 0; axis < 3; ++axis) {
      ExpectClose(b.translation_bounds[axis], a.translation_bounds[axis], 0.03,
                  "translation bound");
      EXPECT_DOUBLE_EQ(b.rotation_bounds[axis], a.rotation_bounds[axis]);
    }
    // A 95th percentile of the sample varies more than its RMS.
    ExpectClose(b.map_max_range, a.map_max_range, 0.05, "ray length");
  }
}

INSTANTIATE_TEST_SUITE_P(SharedData, FarReturns,
                         ::testing::Values(ScanDataset{"kitti00", false},
                                           ScanDataset{"7scenes_redkitchen", true},
                                           ScanDataset{"bunny", false}),
                         [](const ::testing::TestParamInfo<ScanDataset>& info) {
                           return TestName(info.param.name);
                         });

}  // namespace
}  // namespace boicp
