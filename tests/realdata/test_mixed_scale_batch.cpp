// A batch whose scans change scale half way, as a drive from the open into a
// space eight times smaller: KITTI scans 0-4 as they are, then scans 5-9
// shrunk to 1/8. Its settings are chosen once, from 5 scans of which 3 are
// full size, so the small scans' pairs need those settings scaled by 1/8
// (PairScaleStep). Every reference pair within either half must be found
// within 0.5 degrees and 2 cm, the small half's 2 cm shrunk with it: the
// accuracy the full-size pairs reach. Searched at the full-size settings
// alone, the small pairs miss it (the test prints how many are right).

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "../support/files_and_processes.hpp"
#include "boicp/mapping/fusion_memory.hpp"
#include "boicp/mapping/map_batch.hpp"
#include "boicp/mapping/pair_scheduler.hpp"
#include "boicp/util/thread_pool.hpp"
#include "evaluation.hpp"
#include "shared_data.hpp"

namespace boicp {
namespace {

constexpr int kScans = 10;
constexpr int kFirstSmallScan = 5;
constexpr double kSmallScale = 1.0 / 8.0;

class DiscardingStore : public PairStore {
 public:
  std::vector<PairResult> LoadFinished() override { return {}; }
  void Save(int, const PairResult&) override {}
  void MarkInGraph(const std::vector<PairIndex>&,
                   const std::map<PairIndex, std::string>&) override {}
};

// KITTI scan `index`'s file name, as pairs.csv names it.
std::string ScanName(int index) {
  char name[32];
  std::snprintf(name, sizeof(name), "velodyne/%06d.bin", index);
  return name;
}

struct ReferenceWithin {
  PairIndex pair;
  Transform T_target_source;
};

// The reference pairs within one half, with the small half's translations shrunk.
std::vector<ReferenceWithin> PairsWithinHalves(const std::filesystem::path& folder) {
  // velodyne/000007.bin is scan 7.
  const auto index = [](const std::string& path) {
    return std::stoi(std::filesystem::path(path).stem().string());
  };
  std::vector<ReferenceWithin> pairs;
  for (const ReferencePair& reference : ReadPairsCsv((folder / "pairs.csv").string())) {
    const int source = index(reference.source), target = index(reference.target);
    const bool small = source >= kFirstSmallScan;
    if (small != (target >= kFirstSmallScan)) continue;
    Transform expected = reference.T_target_source;
    if (small) expected.block<3, 1>(0, 3) *= kSmallScale;
    pairs.push_back({{source, target}, expected});
  }
  return pairs;
}

std::map<PairIndex, PairResult> RegisterPairs(const MapBatch& batch, const BatchScale& scale,
                                              const std::vector<ReferenceWithin>& references) {
  std::vector<PairIndex> pairs;
  for (const ReferenceWithin& reference : references) pairs.push_back(reference.pair);
  ThreadPool pool(2);
  PairExecution execution;
  execution.submit = [&pool](std::function<void()> task) { pool.Submit(std::move(task)); };
  execution.max_in_flight = pool.size();
  DiscardingStore store;
  MapProgressSink progress;
  return RegisterPlannedPairs(batch.scans, batch.config, scale, PlanFixedPairs(pairs), store,
                              progress, execution)
      .finished;
}

TEST(MixedScaleBatch, EachHalfIsSearchedAtItsOwnScale) {
  const std::filesystem::path folder = SharedDataFolder("kitti00");
  if (const std::string missing = MissingSharedData(folder); !missing.empty())
    GTEST_SKIP() << missing;
  test::ScratchDir dir("boicp_mixed_scale");
  MapBatch batch;
  for (int i = 0; i < kScans; ++i) {
    Points points = LoadPointCloud((folder / ScanName(i)).string()).points;
    if (i >= kFirstSmallScan) {
      for (Point& p : points) p *= kSmallScale;
    }
    ScanSource scan;
    scan.path = (dir.path() / (std::to_string(i) + ".pcd")).string();
    std::ofstream(scan.path, std::ios::binary) << EncodeBinaryPcd(points);
    batch.scans.push_back(scan);
  }
  ChooseBatchSettings(batch, ProfileScans(batch.scans, 2));
  const BatchScale& scale = batch.scale;
  for (int i = 0; i < kScans; ++i) {
    EXPECT_EQ(ScanAtAnotherScale(scale, static_cast<size_t>(i)), i >= kFirstSmallScan)
        << "scan " << i << " reaches " << scale.scan_ranges[static_cast<size_t>(i)] << " m against "
        << scale.reference_range << " m";
  }

  const std::vector<ReferenceWithin> references = PairsWithinHalves(folder);
  ASSERT_GE(references.size(), 8u);
  const std::map<PairIndex, PairResult> scaled = RegisterPairs(batch, scale, references);
  const std::map<PairIndex, PairResult> unscaled = RegisterPairs(batch, BatchScale{}, references);
  int unscaled_right = 0;
  for (const ReferenceWithin& reference : references) {
    const bool small = reference.pair.source >= kFirstSmallScan;
    const double max_translation = small ? 0.02 * kSmallScale : 0.02;
    const auto right = [&](const PairResult& result) {
      return RotationErrorDeg(result.transform, reference.T_target_source) < 0.5 &&
             TranslationErrorM(result.transform, reference.T_target_source) < max_translation;
    };
    const PairResult& result = scaled.at(reference.pair);
    EXPECT_EQ(PairScaleStep(scale, reference.pair), small ? -3 : 0);
    EXPECT_TRUE(right(result)) << reference.pair.source << " -> " << reference.pair.target << ": "
                               << RotationErrorDeg(result.transform, reference.T_target_source)
                               << " deg, "
                               << TranslationErrorM(result.transform, reference.T_target_source)
                               << " m";
    unscaled_right += right(unscaled.at(reference.pair));
  }
  // For the record: the same pairs at the batch's settings alone.
  std::printf("at the batch's settings alone: %d of %zu pairs right\n", unscaled_right,
              references.size());
}

}  // namespace
}  // namespace boicp
