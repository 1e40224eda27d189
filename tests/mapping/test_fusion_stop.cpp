// A stop request (a cancel or a drain) reaches into fusion's long steps: the
// ray casting and tree update of one scan, and the writing of a tree. Each
// test fires the request at a point a between-scans check cannot see, and
// checks that the work ends there, with no output left behind.

#include <atomic>
#include <filesystem>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "../support/files_and_processes.hpp"
#include "boicp/io/synthetic_scene.hpp"
#include "boicp/mapping/map_assembly.hpp"

namespace boicp {
namespace {
using boicp::test::HasStagingFile;

namespace fs = std::filesystem;

class FusionStop : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("boicp_fusion_stop_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir_);
    const Points world = MakeSyntheticStreet(5, 20.0);
    for (size_t i = 0; i < 2; ++i) {
      poses_.push_back(PoseFromYawTranslation(0.1 * static_cast<double>(i), {2.0 * i, 0, 0}));
      ScanSource scan;
      scan.path = (dir_ / ("scan" + std::to_string(i) + ".xyz")).string();
      WriteXyz(scan.path, SimulateScan(world, poses_[i], 25.0, 0.0, i));
      scans_.push_back(scan);
    }
    settings_.occupancy.resolution = 0.1;
    settings_.occupancy.max_range = 25.0;
    outputs_.octomap_ot = (dir_ / "map.ot").string();
    outputs_.octomap_bt = (dir_ / "map.bt").string();
  }
  void TearDown() override { fs::remove_all(dir_); }

  // Fuses the two scans with `stop_requested`; returns how many scans were
  // reported fused before it ended.
  int FuseUntilStopped(const AssemblyCallbacks& callbacks_in) {
    AssemblyCallbacks callbacks = callbacks_in;
    int fused = 0;
    const auto report = callbacks.progress;
    callbacks.progress = [&](const AssemblyProgress& p) {
      if (p.stage == MapStage::kFusing) fused = p.done;
      if (report) report(p);
    };
    EXPECT_THROW(FuseScans(scans_, poses_, settings_, outputs_, callbacks), Cancelled);
    return fused;
  }

  void ExpectNoOutputs() const {
    EXPECT_FALSE(fs::exists(outputs_.octomap_ot));
    EXPECT_FALSE(fs::exists(outputs_.octomap_bt));
    EXPECT_FALSE(HasStagingFile(dir_));
  }

  fs::path dir_;
  std::vector<ScanSource> scans_;
  std::vector<Transform> poses_;
  MapBuildSettings settings_;
  MapOutputPaths outputs_;
};

// The first poll is the check before scan 0; the second comes from inside
// its ray casting, so the scan must not be reported fused.
TEST_F(FusionStop, StopDuringTheFirstScanEndsItsRayCasting) {
  for (const int threads : {1, 2}) {
    settings_.fusion_threads = threads;
    std::atomic<int> polls{0};
    AssemblyCallbacks callbacks;
    callbacks.stop_requested = [&polls] { return ++polls >= 2; };
    EXPECT_EQ(FuseUntilStopped(callbacks), 0) << threads << " threads";
    ExpectNoOutputs();
  }
}

// The request fires once writing begins: before the .ot is complete, not
// between two outputs.
TEST_F(FusionStop, StopDuringWritingLeavesNoTree) {
  std::atomic<bool> writing{false};
  AssemblyCallbacks callbacks;
  callbacks.progress = [&writing](const AssemblyProgress& p) {
    if (p.stage == MapStage::kWriting) writing = true;
  };
  callbacks.stop_requested = [&writing] { return writing.load(); };
  // Only the polls from inside the .ot write can see it: the between-output
  // checks come after the file is renamed into place.
  EXPECT_EQ(FuseUntilStopped(callbacks), 2);
  ExpectNoOutputs();
}

TEST_F(FusionStop, EachStepOfOneScanStopsOnRequest) {
  OccupancyMap map(settings_.occupancy);
  const Points points = LoadPointCloud(scans_[0].path, {}).points;
  const MapStopRequest always = [] { return true; };
  EXPECT_THROW(map.ComputeUpdate(points, poses_[0], Point::Zero(), 2, always), Cancelled);
  const ScanUpdate update = map.ComputeUpdate(points, poses_[0], Point::Zero(), 2);
  ASSERT_GT(update.FreeCells(), 100000u) << "the scan is too small to poll during its update";
  EXPECT_THROW(map.ApplyUpdate(update, always), Cancelled);

  OccupancyMap whole(settings_.occupancy);
  whole.ApplyUpdate(update);
  const std::string ot = (dir_ / "direct.ot").string(), bt = (dir_ / "direct.bt").string();
  EXPECT_THROW(whole.WriteFull(ot, always), Cancelled);
  EXPECT_THROW(whole.WriteBinary(bt, always), Cancelled);
  // Without a request, the same map writes whole files.
  whole.WriteFull(ot);
  whole.WriteBinary(bt);
  EXPECT_GT(fs::file_size(ot), 100000u);
  EXPECT_GT(fs::file_size(bt), 10000u);
}

}  // namespace
}  // namespace boicp
