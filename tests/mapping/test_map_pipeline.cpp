// Core's map pipeline scheduling (core/pair_scheduler, map_pipeline) with a
// store in memory: what it reuses, what it reports, how it fails and stops,
// and the pose-graph edges it assembles from.

#include <atomic>
#include <map>
#include <mutex>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "boicp/mapping/map_pipeline.hpp"
#include "boicp/util/thread_pool.hpp"
#include "boicp/util/types.hpp"

namespace boicp {
namespace {

using ::testing::ElementsAre;
using ::testing::HasSubstr;

PairResult Finished(int source, int target, double overlap) {
  PairResult finished;
  finished.pair = {source, target};
  finished.overlap = overlap;
  finished.transform = Transform::Identity();
  finished.transform(0, 3) = 2.0;  // the source 2 m further along x
  return finished;
}

class MemoryStore : public PairStore {
 public:
  explicit MemoryStore(std::vector<PairResult> stored) : stored_(std::move(stored)) {}
  std::vector<PairResult> LoadFinished() override { return stored_; }
  void Save(int, const PairResult& result) override {
    std::lock_guard<std::mutex> lock(mutex_);
    saved_.push_back(result.pair);
  }
  void MarkInGraph(const std::vector<PairIndex>& in_graph,
                   const std::map<PairIndex, std::string>&) override {
    in_graph_ = in_graph;
  }

  std::vector<PairResult> stored_;
  std::mutex mutex_;
  std::vector<PairIndex> saved_;
  std::vector<PairIndex> in_graph_;
};

class RecordingProgress : public MapProgressSink {
 public:
  void PairFinished(const PairResult& pair, bool reused, const PairCounts& counts) override {
    finished.push_back(pair.pair);
    reused_count += reused;
    last = counts;
  }
  void PairFailed(const PairIndex& pair, const std::string& message) override {
    failed.push_back(pair);
    failure = message;
  }
  std::vector<PairIndex> finished;
  std::vector<PairIndex> failed;
  std::string failure;
  int reused_count = 0;
  PairCounts last;
};

// Scans that do not exist: any registration fails to load them.
std::vector<ScanSource> MissingScans(int n) {
  std::vector<ScanSource> scans(static_cast<size_t>(n));
  for (int i = 0; i < n; ++i) {
    scans[static_cast<size_t>(i)].path = "/nonexistent/boicp/scan" + std::to_string(i) + ".xyz";
    scans[static_cast<size_t>(i)].load.format = CloudFormat::kXyz;
  }
  return scans;
}

// The preset's settings as final: a batch chooses its settings before it
// registers (ApplyBatchSettings).
BoIcpConfig FinalConfig() {
  BoIcpConfig config;
  config.automatic.clear();
  return config;
}

PairExecution OnPool(ThreadPool& pool, std::function<bool()> stop = {}) {
  PairExecution execution;
  execution.submit = [&pool](std::function<void()> task) { pool.Submit(std::move(task)); };
  execution.max_in_flight = pool.size();
  execution.stop_requested = std::move(stop);
  return execution;
}

TEST(MapPipeline, StoredPairsAreReusedAndNothingIsRegisteredAgain) {
  ThreadPool pool(2);
  MemoryStore store({Finished(1, 2, 0.9), Finished(0, 1, 0.9), Finished(7, 8, 0.9)});
  RecordingProgress progress;
  const RegisteredPairs registered =
      RegisterPlannedPairs(MissingScans(3), FinalConfig(), BatchScale{},
                           PlanFixedPairs(ConsecutivePairs(3)), store, progress, OnPool(pool));
  EXPECT_TRUE(store.saved_.empty());
  // In plan order; a stored pair the plan does not hold is ignored.
  EXPECT_THAT(progress.finished, ElementsAre(PairIndex{0, 1}, PairIndex{1, 2}));
  EXPECT_EQ(progress.reused_count, 2);
  EXPECT_EQ(registered.finished.size(), 2u);
  EXPECT_THAT(registered.chain, ElementsAre(PairIndex{0, 1}, PairIndex{1, 2}));
}

// The keyframe chain follows the recorded overlaps only: scan 3 sees too
// little of keyframe 0, so scan 2 becomes the keyframe and 3 hangs off it.
TEST(MapPipeline, KeyframeChainComesFromTheStoredOverlaps) {
  ThreadPool pool(2);
  MemoryStore store({Finished(1, 0, 0.9), Finished(2, 0, 0.8), Finished(3, 0, 0.2),
                     Finished(3, 2, 0.9), Finished(0, 1, 0.9)});
  RecordingProgress progress;
  const RegisteredPairs registered =
      RegisterPlannedPairs(MissingScans(4), FinalConfig(), BatchScale{}, PlanKeyframes(0.7), store,
                           progress, OnPool(pool));
  EXPECT_TRUE(store.saved_.empty());
  EXPECT_THAT(registered.chain, ElementsAre(PairIndex{1, 0}, PairIndex{2, 0}, PairIndex{3, 2}));
  // The probe 3 -> 0 is kept (listed), the consecutive-direction 0 -> 1 is not the plan's.
  EXPECT_EQ(registered.finished.size(), 4u);
  EXPECT_EQ(progress.last.total, 4);
}

TEST(MapPipeline, AFailedPairIsReportedAndRethrownAfterTheOthersStop) {
  ThreadPool pool(2);
  MemoryStore store({});
  RecordingProgress progress;
  EXPECT_THROW(
      RegisterPlannedPairs(MissingScans(4), FinalConfig(), BatchScale{},
                           PlanFixedPairs(ConsecutivePairs(4)), store, progress, OnPool(pool)),
      InputError);
  ASSERT_EQ(progress.failed.size(), 1u);
  EXPECT_THAT(progress.failure, HasSubstr("scan"));
  EXPECT_TRUE(store.saved_.empty());
}

TEST(MapPipeline, AStopRequestEndsRegistrationWithCancelled) {
  ThreadPool pool(1);
  MemoryStore store({});
  RecordingProgress progress;
  EXPECT_THROW(RegisterPlannedPairs(MissingScans(4), FinalConfig(), BatchScale{},
                                    PlanFixedPairs(ConsecutivePairs(4)), store, progress,
                                    OnPool(pool, [] { return true; })),
               Cancelled);
  EXPECT_TRUE(progress.failed.empty());
}

TEST(MapPipeline, GraphEdgesAreTheChainThenExtrasNotPairingTheSameScans) {
  RegisteredPairs registered;
  for (const PairResult& f :
       {Finished(1, 0, 1), Finished(2, 1, 1), Finished(1, 2, 1), Finished(2, 0, 1)}) {
    registered.finished[f.pair] = f;
  }
  registered.chain = {{1, 0}, {2, 1}};
  const PairingPlan plan = PlanKeyframes(0.7, {{1, 2}, {2, 0}});
  const GraphEdges edges = GraphConstraints(plan, registered);
  EXPECT_THAT(edges.pairs, ElementsAre(PairIndex{1, 0}, PairIndex{2, 1}, PairIndex{2, 0}));
  ASSERT_EQ(edges.constraints.size(), 3u);
  EXPECT_EQ(edges.constraints[2].pair, (PairIndex{2, 0}));
  PoseEstimate estimate;
  estimate.kept = {true, true, false};
  EXPECT_THAT(PairsInGraph(edges, estimate), ElementsAre(PairIndex{1, 0}, PairIndex{2, 1}));
}

// The closing line counts loops as the issue names them, in good English.
TEST(MapPipeline, TheLoopLineCountsClosedLoopsAndCandidates) {
  EXPECT_EQ(LoopStageSummary{}.Line(), "");
  EXPECT_EQ((LoopStageSummary{1, 1, 1.0, 50.0}.Line()),
            "1 loop closed of 1 candidate; verifying them took 1 s, 2 % of the other pairs' 50 s");
  EXPECT_THAT((LoopStageSummary{40, 12, 30.0, 120.0}.Line()),
              ::testing::StartsWith("12 loops closed of 40 candidates; verifying them took 30 s, "
                                    "25 %"));
}

}  // namespace
}  // namespace boicp
