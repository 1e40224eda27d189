// One batch from any front end's request (settings::MakeMapBatch), and the
// settings chosen once for it from its scans (ChooseBatchSettings).

#include <filesystem>
#include <fstream>
#include <vector>

#include <gmock/gmock.h>

#include "../support/demo_sequence.hpp"
#include "../support/files_and_processes.hpp"
#include "boicp/mapping/fusion_memory.hpp"
#include "boicp/settings/map_batch_request.hpp"

namespace boicp::settings {
namespace {

using ::testing::ElementsAre;
using ::testing::HasSubstr;
using ::testing::StartsWith;

std::vector<ScanSource> NamedScans(int n) {
  std::vector<ScanSource> scans(static_cast<size_t>(n));
  for (int i = 0; i < n; ++i) scans[static_cast<size_t>(i)].path = std::to_string(i) + ".bin";
  return scans;
}

std::string ErrorOf(const RequestedSettings& requested, const PairingRequest& pairing,
                    const std::string& pairs_source = "pairing.pairs") {
  try {
    MakeMapBatch(NamedScans(4), requested, pairing, 1, pairs_source);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(MakeMapBatch, PlansTheRequestWithItsSettingsAndThreads) {
  RequestedSettings requested;
  requested.preset = "A";
  requested.seed = 7;
  requested.resolution = 0.3;
  PairingRequest pairing;
  pairing.pairs = {{3, 0}};
  const MapBatch batch = MakeMapBatch(NamedScans(4), requested, pairing, 3);

  EXPECT_EQ(batch.scans.size(), 4u);
  EXPECT_EQ(batch.scans[2].path, "2.bin");
  EXPECT_EQ(batch.config.preset, "A");
  EXPECT_EQ(batch.config.seed, 7u);
  EXPECT_EQ(batch.config.threads, 3);
  EXPECT_EQ(batch.map.occupancy.resolution, 0.3);
  EXPECT_FALSE(batch.map_auto.resolution) << "set by the request";
  EXPECT_TRUE(batch.map_auto.max_range) << "left to the scans";
  EXPECT_EQ(batch.pairing.mode, PairingMode::kConsecutive);
  EXPECT_FALSE(batch.plan.keyframes);
  EXPECT_EQ(batch.plan.chain.size(), 3u);
  EXPECT_THAT(batch.plan.extras, ElementsAre(PairIndex{3, 0}));
  EXPECT_THAT(batch.pairing.pairs, ElementsAre(PairIndex{3, 0}));
}

TEST(MakeMapBatch, AnOverlapRequestPlansKeyframesAtItsThreshold) {
  PairingRequest pairing;
  pairing.mode = PairingMode::kOverlap;
  pairing.overlap_threshold = 0.8;
  const MapBatch batch = MakeMapBatch(NamedScans(4), {}, pairing, 1);
  EXPECT_TRUE(batch.plan.keyframes);
  EXPECT_EQ(batch.plan.overlap_threshold, 0.8);
}

TEST(MakeMapBatch, ABadSettingNamesItsGroupOnce) {
  RequestedSettings bad_config;
  bad_config.voxel = -1.0;
  EXPECT_THAT(ErrorOf(bad_config, {}), StartsWith("config: "));

  RequestedSettings bad_map;
  bad_map.resolution = -1.0;
  EXPECT_THAT(ErrorOf(bad_map, {}), StartsWith("map settings: "));

  // MapBuildFromSettings already names the group of this one.
  RequestedSettings bad_cloud;
  bad_cloud.cloud_voxel = -1.0;
  const std::string message = ErrorOf(bad_cloud, {});
  EXPECT_THAT(message, StartsWith("map settings: cloud_voxel"));
  EXPECT_THAT(message, ::testing::Not(HasSubstr("map settings: map settings")));
}

TEST(MakeMapBatch, APairOutsideTheScansNamesWhereThePairsCameFrom) {
  PairingRequest pairing;
  pairing.pairs = {{0, 9}};
  EXPECT_THAT(ErrorOf({}, pairing, "loops.txt"), HasSubstr("loops.txt"));
  EXPECT_THAT(ErrorOf({}, pairing), HasSubstr("pairing.pairs"));
}

TEST(ChooseBatchSettings, ChoosesWhatApplyBatchSettingsChoosesAndLeavesNothingAutomatic) {
  test::ScratchDir dir("boicp_map_batch");
  std::vector<ScanSource> scans;
  int i = 0;
  for (const test::GeneratedScan& scan : test::MakeDemoSequence(3, 5)) {
    ScanSource source;
    source.path = (dir.path() / (std::to_string(i++) + ".bin")).string();
    std::ofstream(source.path, std::ios::binary) << scan.kitti_bytes;
    scans.push_back(source);
  }
  MapBatch batch = MakeMapBatch(scans, {}, {}, 1);
  ASSERT_FALSE(batch.config.automatic.empty());
  ASSERT_TRUE(batch.map_auto.resolution);
  MapBatch expected = batch;
  const BatchSettingsChoice applied = ApplyBatchSettings(expected.scans, expected.config,
                                                         expected.map.occupancy, expected.map_auto);

  const BatchSettingsChoice chosen = ChooseBatchSettings(batch, ProfileScans(batch.scans, 1));
  EXPECT_EQ(chosen.fields, applied.fields);
  EXPECT_EQ(chosen.sensor, applied.sensor);
  EXPECT_EQ(batch.config.voxel, expected.config.voxel);
  EXPECT_EQ(batch.config.translation_bounds, expected.config.translation_bounds);
  EXPECT_EQ(batch.map.occupancy.resolution, expected.map.occupancy.resolution);
  EXPECT_EQ(batch.map.occupancy.max_range, expected.map.occupancy.max_range);
  EXPECT_TRUE(batch.config.automatic.empty());
  EXPECT_FALSE(batch.map_auto.resolution);
  EXPECT_FALSE(batch.map_auto.max_range);
  // One drive at one scale: every pair keeps the batch's settings.
  EXPECT_GT(batch.scale.reference_range, 0.0);
  EXPECT_EQ(batch.scale.scan_ranges.size(), scans.size());
  EXPECT_EQ(PairScaleStep(batch.scale, {4, 0}), 0);
}

}  // namespace
}  // namespace boicp::settings
