// Cancellation (running and queued jobs) and two clients at once.

#include <chrono>
#include <thread>

#include <gmock/gmock.h>

#include "server_fixture.hpp"

namespace boicp::test {
namespace {

class CancelAndConcurrency : public ServerTest {};

TEST_F(CancelAndConcurrency, CancelStopsARunningBatchMidwayAndAQueuedOneAtOnce) {
  StartDaemon({"--workers", "2", "--jobs", "1"});
  auto client = Client();
  const auto ids = UploadDrive(client, 5, 51);
  // Config C: long enough that the cancel lands mid-search.
  const v1::SubmitBatchRequest slow = SlowBatch(ids);
  const std::string running = client.Submit(slow).job_id();
  const std::string queued = client.Submit(slow).job_id();
  const v1::Job started = PollJob(
      client, running, [](const v1::Job& j) { return j.state() == v1::JOB_STATE_RUNNING; }, 60);
  ASSERT_EQ(started.state(), v1::JOB_STATE_RUNNING);
  std::this_thread::sleep_for(std::chrono::milliseconds(500));

  const v1::Job cancelled_queued = client.Cancel(queued);
  EXPECT_EQ(cancelled_queued.state(), v1::JOB_STATE_CANCELLED);

  // Stopped midway: the batch has 4 pairs. (How fast is not asserted: these
  // machines are shared; a cancel that never lands hits the test timeout.)
  EXPECT_TRUE(client.Cancel(running).cancel_requested());
  const v1::Job end = client.Watch(running);
  EXPECT_EQ(end.state(), v1::JOB_STATE_CANCELLED);
  EXPECT_LT(end.pairs_done(), 4u);

  // A cancelled job has no outputs; cancelling it again changes nothing.
  try {
    client.ExportToFile(running, v1::EXPORT_FORMAT_OCTOMAP_BT, (dir_ / "x.bt").string());
    ADD_FAILURE() << "export of a cancelled job succeeded";
  } catch (const rpc::RpcError& e) {
    EXPECT_EQ(e.code(), grpc::StatusCode::FAILED_PRECONDITION);
  }
  EXPECT_EQ(client.Cancel(running).state(), v1::JOB_STATE_CANCELLED);
}

TEST_F(CancelAndConcurrency, TwoClientsSubmittingConcurrentlyBothComplete) {
  StartDaemon({"--workers", "2", "--jobs", "2"});
  std::vector<v1::Job> ends(2);
  std::vector<std::thread> clients;
  for (int c = 0; c < 2; ++c) {
    clients.emplace_back([this, c, &ends] {
      auto client = Client();  // its own channel
      const auto ids = UploadDrive(client, 4, 60 + static_cast<uint64_t>(c));
      ends[static_cast<size_t>(c)] = client.Watch(client.Submit(QuickBatch(ids)).job_id());
    });
  }
  for (std::thread& t : clients) t.join();
  for (const v1::Job& job : ends) {
    EXPECT_EQ(job.state(), v1::JOB_STATE_SUCCEEDED) << job.job_id() << ": " << job.error();
    EXPECT_EQ(job.pairs_done(), 3u);
  }
  EXPECT_NE(ends[0].job_id(), ends[1].job_id());
}

Transform FromProto(const v1::Transform& proto) {
  Transform T;
  for (int k = 0; k < 16; ++k) T(k / 4, k % 4) = proto.m(k);
  return T;
}

// Two loop closures: 3 -> 0 (6 m apart, registered exactly) and 4 -> 0 (8 m
// apart along a street of repeated poles, which the quick search gets wrong
// by about 1.6 m with these seeds). The pose graph keeps the first and prunes
// a wrong second, in both pairing modes.
TEST_F(CancelAndConcurrency, LoopClosuresOptimiseThePoseGraphAndWrongOnesArePruned) {
  StartDaemon({"--workers", "2", "--jobs", "2"});
  auto client = Client();
  std::vector<Transform> truth;
  const auto ids = UploadDrive(client, 5, 71, &truth);
  v1::SubmitBatchRequest consecutive = QuickBatch(ids);
  for (uint32_t source : {3u, 4u}) {
    v1::Pair* loop = consecutive.mutable_pairing()->add_pairs();
    loop->set_source(source);
    loop->set_target(0);
  }
  v1::SubmitBatchRequest keyframes = consecutive;
  keyframes.mutable_pairing()->set_mode(v1::PairingPolicy::MODE_OVERLAP);
  // No two scans 4 m apart overlap this much, so every scan becomes a
  // keyframe after one wasted probe: chain (1,0) (2,1) (3,2) (4,3).
  keyframes.mutable_pairing()->set_overlap_threshold(0.999);
  const std::string first = client.Submit(keyframes).job_id();
  const std::string second = client.Submit(consecutive).job_id();

  for (const std::string& job_id : {first, second}) {
    const v1::Job done = client.Watch(job_id);
    ASSERT_EQ(done.state(), v1::JOB_STATE_SUCCEEDED) << done.error();
    EXPECT_TRUE(done.pose_graph_optimised()) << job_id;
    const v1::JobResults results = client.Results(done.job_id());
    ASSERT_EQ(results.trajectory_size(), 5);
    int in_graph = 0;
    for (const v1::PairResult& p : results.pairs()) {
      in_graph += p.in_graph();
      if (p.target() != 0 || p.source() < 3) continue;
      const Transform reference = truth[0].inverse() * truth[p.source()];
      const double error =
          (FromProto(p.transform()).topRightCorner<3, 1>() - reference.topRightCorner<3, 1>())
              .norm();
      EXPECT_EQ(p.in_graph(), error < 0.3)
          << job_id << " loop closure " << p.source() << "->0 is off by " << error << " m";
      EXPECT_EQ(p.in_graph(), p.left_out_because().empty()) << p.left_out_because();
    }
    EXPECT_GE(in_graph, 5) << "4 chain pairs and at least the good loop closure";
    for (int i = 1; i < 5; ++i) {
      const Transform pose = FromProto(results.trajectory(i).pose());
      const Transform expected = truth[0].inverse() * truth[static_cast<size_t>(i)];
      EXPECT_LT((pose.topRightCorner<3, 1>() - expected.topRightCorner<3, 1>()).norm(), 0.1)
          << job_id << " scan " << i;
    }
  }
}

}  // namespace
}  // namespace boicp::test
