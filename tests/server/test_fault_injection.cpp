// Fault injection: boicpd is SIGKILLed at a seeded random point of a small
// batch (while its scans upload, while its pairs register, while its map is
// fused, or while its output files are written) and restarted on the same data directory, cycle
// after cycle, each cycle on a fresh data directory. Every batch must end
// exactly as an uninterrupted run of it: the same pair transforms and poses
// (within 1e-9) and the same map and trajectory files.
//
// BOICP_FAULT_CYCLES (default 24) and BOICP_FAULT_SEED (default 1) change the
// run; the figures are printed and written to BOICP_FAULT_REPORT (default
// fault_injection.txt in the working directory, which outlives the test's
// temporary directory).

#include <signal.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <map>
#include <random>
#include <sstream>
#include <thread>

#include <gmock/gmock.h>

#include "../support/demo_sequence.hpp"
#include "../support/files_and_processes.hpp"
#include "server_fixture.hpp"

namespace boicp::test {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

constexpr int kScans = 4;  // 3 consecutive pairs
constexpr uint64_t kDriveSeed = 91, kBatchSeed = 7;
constexpr size_t kUploadChunk = 64 << 10;
constexpr double kTolerance = 1e-9;
const std::vector<std::string> kDaemonArgs = {"--workers", "2"};

enum Phase { kUpload, kRegistration, kFusion, kWriting, kPhases };
const char* const kPhaseNames[kPhases] = {"upload", "registration", "fusion", "writing"};

uint64_t EnvOr(const char* name, uint64_t fallback) {
  const char* value = std::getenv(name);
  return value && *value ? std::strtoull(value, nullptr, 10) : fallback;
}

double Seconds(Clock::duration d) { return std::chrono::duration<double>(d).count(); }

// "2 of 5 outputs written, a staging file left" for a killed job's directory.
std::string OutputsOnDisk(const fs::path& job_dir) {
  if (!fs::exists(job_dir)) return "no job directory yet";
  int written = 0;
  for (const char* name : {"map.bt", "map.ot", "map.ply", "trajectory.tum", "trajectory.kitti"}) {
    written += fs::exists(job_dir / name);
  }
  return std::to_string(written) + " of 5 outputs written" +
         (HasStagingFile(job_dir) ? ", a staging file left" : "");
}

bool IsAssemblyStage(const std::string& stage) {
  return stage == "chaining" || stage == "optimising" || stage == "fusing";
}

// What a finished batch left: its results and two of its output files.
struct BatchOutput {
  v1::JobResults results;
  std::string map_bt, trajectory_tum;
};

// Differences between `got` and `want`, one line each; empty when equal.
std::vector<std::string> Differences(const BatchOutput& got, const BatchOutput& want) {
  std::vector<std::string> found;
  auto near = [](const v1::Transform& a, const v1::Transform& b) {
    if (a.m_size() != 16 || b.m_size() != 16) return false;
    for (int k = 0; k < 16; ++k) {
      if (std::abs(a.m(k) - b.m(k)) > kTolerance) return false;
    }
    return true;
  };
  std::map<std::pair<uint32_t, uint32_t>, v1::PairResult> wanted;
  for (const v1::PairResult& p : want.results.pairs()) wanted[{p.source(), p.target()}] = p;
  if (got.results.pairs_size() != want.results.pairs_size()) found.push_back("pair count");
  for (const v1::PairResult& p : got.results.pairs()) {
    const auto other = wanted.find({p.source(), p.target()});
    if (other == wanted.end() || other->second.seed() != p.seed() ||
        !near(p.transform(), other->second.transform())) {
      found.push_back("pair " + std::to_string(p.source()) + "->" + std::to_string(p.target()));
    }
  }
  if (got.results.trajectory_size() != want.results.trajectory_size()) {
    found.push_back("trajectory length");
  } else {
    for (int i = 0; i < got.results.trajectory_size(); ++i) {
      if (!near(got.results.trajectory(i).pose(), want.results.trajectory(i).pose())) {
        found.push_back("pose " + std::to_string(i));
      }
    }
  }
  if (got.map_bt != want.map_bt) found.push_back("map.bt bytes");
  if (got.trajectory_tum != want.trajectory_tum) found.push_back("trajectory.tum bytes");
  return found;
}

class FaultInjection : public ServerTest {
 protected:
  void SetUp() override {
    ServerTest::SetUp();
    drive_ = test::MakeDemoSequence(kScans, kDriveSeed);
  }

  std::vector<std::string> UploadAll(rpc::MapBuilderClient& client, int count) {
    std::vector<std::string> ids;
    for (int i = 0; i < count; ++i) {
      ids.push_back(client
                        .Upload(drive_[static_cast<size_t>(i)].kitti_bytes,
                                Meta(v1::SCAN_FORMAT_KITTI_BIN, 0))
                        .scan_id());
    }
    return ids;
  }

  BatchOutput Collect(rpc::MapBuilderClient& client, const std::string& job_id) {
    BatchOutput out;
    out.results = client.Results(job_id);
    const fs::path bt = dir_ / "export.bt", tum = dir_ / "export.tum";
    client.ExportToFile(job_id, v1::EXPORT_FORMAT_OCTOMAP_BT, bt.string());
    client.ExportToFile(job_id, v1::EXPORT_FORMAT_TRAJECTORY_TUM, tum.string());
    out.map_bt = Slurp(bt);
    out.trajectory_tum = Slurp(tum);
    return out;
  }

  void Kill() {
    daemon_->Signal(SIGKILL);
    ASSERT_EQ(daemon_->Wait(10), 128 + SIGKILL);
  }

  // Streams scans[0..k) whole and part of scan k, then kills the daemon
  // mid-stream. Returns where; `cut` tells whether the upload failed, and
  // `cut_id` is scan k's id.
  std::string KillDuringUpload(rpc::MapBuilderClient& client, std::mt19937_64& rng, bool* cut,
                               std::string* cut_id) {
    const int k = std::uniform_int_distribution<int>(0, kScans - 1)(rng);
    UploadAll(client, k);
    const std::string& bytes = drive_[static_cast<size_t>(k)].kitti_bytes;
    *cut_id = rpc::ScanId(bytes);
    const size_t chunks = (bytes.size() + kUploadChunk - 1) / kUploadChunk;
    const size_t sent = std::uniform_int_distribution<size_t>(0, chunks - 1)(rng);
    grpc::ClientContext context;
    v1::UploadScanResponse response;
    auto writer = client.stub().UploadScan(&context, &response);
    v1::UploadScanRequest message;
    *message.mutable_metadata() = Meta(v1::SCAN_FORMAT_KITTI_BIN, bytes.size());
    writer->Write(message);
    for (size_t c = 0; c < sent; ++c) {
      message.set_chunk(bytes.substr(c * kUploadChunk, kUploadChunk));
      writer->Write(message);
    }
    Kill();
    writer->WritesDone();
    *cut = !writer->Finish().ok();
    std::ostringstream where;
    where << "scan " << k + 1 << " of " << kScans << " cut after " << sent << " of " << chunks
          << " chunks";
    return where.str();
  }

  // Follows the job and kills the daemon when `ready(job)` first holds, after
  // `delay_s`. Returns the job as last seen before the kill.
  v1::Job KillWhen(rpc::MapBuilderClient& client, const std::string& job_id,
                   const std::function<bool(const v1::Job&)>& ready, double delay_s) {
    v1::Job seen;
    bool killed = false;
    try {
      client.Watch(job_id, [&](const v1::JobEvent& event) {
        if (killed) return;
        seen = event.job();
        if (!ready(seen)) return;
        std::this_thread::sleep_for(std::chrono::duration<double>(delay_s));
        Kill();
        killed = true;
      });
    } catch (const rpc::RpcError&) {
      // The stream ends with the daemon.
    }
    if (!killed) Kill();  // the job ended first: the kill missed
    return seen;
  }

  std::vector<test::GeneratedScan> drive_;
};

TEST_F(FaultInjection, SigkillAtRandomPointsThenRestartGivesTheUninterruptedResults) {
  const int cycles = static_cast<int>(EnvOr("BOICP_FAULT_CYCLES", 24));
  const uint64_t seed = EnvOr("BOICP_FAULT_SEED", 1);
  const auto test_start = Clock::now();

  // The uninterrupted run, timed per stage so that kill delays land inside them.
  data_dir_ = dir_ / "reference";
  StartDaemon(kDaemonArgs);
  auto client = Client();
  const std::vector<std::string> ids = UploadAll(client, kScans);
  const v1::SubmitBatchRequest batch = QuickBatch(ids, kBatchSeed);
  const std::string reference_id = client.Submit(batch).job_id();
  std::map<std::string, Clock::time_point> stage_start;  // first event of each stage
  const v1::Job reference_job = client.Watch(reference_id, [&](const v1::JobEvent& event) {
    stage_start.emplace(event.job().stage(), Clock::now());
  });
  ASSERT_EQ(reference_job.state(), v1::JOB_STATE_SUCCEEDED) << reference_job.error();
  for (const char* stage : {"registering", "chaining", "writing", "done"}) {
    ASSERT_EQ(stage_start.count(stage), 1u) << "no event for stage " << stage;
  }
  const double registration_s = Seconds(stage_start["chaining"] - stage_start["registering"]);
  const double fusion_s = Seconds(stage_start["writing"] - stage_start["chaining"]);
  const double writing_s = Seconds(stage_start["done"] - stage_start["writing"]);
  const BatchOutput reference = Collect(client, reference_id);
  const int pairs = reference.results.pairs_size();
  StopDaemon();

  std::mt19937_64 rng(seed);
  int tried[kPhases] = {}, landed[kPhases] = {};
  int accepted = 0, completed = 0, mismatches = 0, identical_files = 0;
  std::vector<double> recovery_s;
  std::ostringstream log;
  for (int cycle = 0; cycle < cycles; ++cycle) {
    const Phase phase = static_cast<Phase>(cycle % kPhases);
    data_dir_ = dir_ / ("cycle-" + std::to_string(cycle));
    StartDaemon(kDaemonArgs);
    client = Client();
    std::string where, job_id;
    bool hit = false;
    if (phase == kUpload) {
      std::string cut_id;
      where = KillDuringUpload(client, rng, &hit, &cut_id);
      StartDaemon(kDaemonArgs);
      client = Client();
      EXPECT_TRUE(fs::is_empty(data_dir_ / "tmp")) << "a cut upload left its temporary file";
      EXPECT_EQ(MissingScans(client, {cut_id}), std::vector<std::string>{cut_id})
          << "a cut upload was stored";
      UploadAll(client, kScans);
      job_id = client.Submit(batch).job_id();
    } else {
      UploadAll(client, kScans);
      job_id = client.Submit(batch).job_id();
      v1::Job seen;
      if (phase == kRegistration) {
        const int after = std::uniform_int_distribution<int>(0, pairs - 1)(rng);
        const double delay =
            std::uniform_real_distribution<double>(0.0, 0.8 * registration_s / pairs)(rng);
        seen = KillWhen(
            client, job_id,
            [&](const v1::Job& j) {
              return j.stage() == "registering" && static_cast<int>(j.pairs_done()) >= after;
            },
            delay);
        where = "after " + std::to_string(after) + " of " + std::to_string(pairs) + " pairs + " +
                std::to_string(static_cast<int>(delay * 1000)) + " ms";
      } else {
        const bool writing = phase == kWriting;
        const double delay = std::uniform_real_distribution<double>(
            0.0, 0.8 * (writing ? writing_s : fusion_s))(rng);
        seen = KillWhen(
            client, job_id,
            [writing](const v1::Job& j) {
              return writing ? j.stage() == "writing" : IsAssemblyStage(j.stage());
            },
            delay);
        where = "stage " + seen.stage() + " + " + std::to_string(static_cast<int>(delay * 1000)) +
                " ms";
      }
      where += " (" + OutputsOnDisk(data_dir_ / "jobs" / job_id) + ")";
      StartDaemon(kDaemonArgs);
      client = Client();
      hit = daemon_->Log().find("job " + job_id + " resumes") != std::string::npos;
    }
    ++accepted;
    const auto restarted = Clock::now();
    const v1::Job done = client.Watch(job_id);
    recovery_s.push_back(Seconds(Clock::now() - restarted));
    std::vector<std::string> differences = {v1::JobState_Name(done.state()) + " " + done.error()};
    if (done.state() == v1::JOB_STATE_SUCCEEDED) {
      ++completed;
      differences = Differences(Collect(client, job_id), reference);
      if (HasStagingFile(data_dir_ / "jobs" / job_id)) {
        differences.push_back("a staging file of the killed run is left in the job directory");
      }
      identical_files +=
          std::none_of(differences.begin(), differences.end(),
                       [](const std::string& d) { return d.find("bytes") != std::string::npos; });
    }
    EXPECT_TRUE(differences.empty()) << "cycle " << cycle << ": " << differences.front();
    mismatches += differences.empty() ? 0 : 1;
    ++tried[phase];
    landed[phase] += hit;
    log << "  cycle " << cycle << " " << kPhaseNames[phase] << ": " << where
        << (hit ? "" : " (missed: nothing was in flight)") << "; "
        << (differences.empty() ? "same results" : "MISMATCH: " + differences.front()) << "\n";
    StopDaemon();
    fs::remove_all(data_dir_);
  }

  std::sort(recovery_s.begin(), recovery_s.end());
  std::ostringstream figures;
  figures << "fault injection: seed " << seed << ", " << cycles << " cycles, " << kScans
          << " scans (" << pairs << " pairs) per batch, boicpd --workers 2\n"
          << "uninterrupted batch: registration " << registration_s << " s, fusion " << fusion_s
          << " s, writing the outputs " << writing_s << " s\n"
          << "kill points tried/landed:";
  for (int p = 0; p < kPhases; ++p) {
    figures << " " << kPhaseNames[p] << " " << tried[p] << "/" << landed[p];
  }
  figures << "\nbatches accepted " << accepted << ", completed " << completed << ", mismatches "
          << mismatches << " (pairs and poses within " << kTolerance
          << "; map.bt and trajectory.tum byte-identical in " << identical_files << " of "
          << completed << ")\n"
          << "restart to finished batch (uploads included after an upload kill): median "
          << recovery_s[recovery_s.size() / 2] << " s, max " << recovery_s.back() << " s\n"
          << "wall time " << Seconds(Clock::now() - test_start) << " s\n"
          << log.str();
  const char* report = std::getenv("BOICP_FAULT_REPORT");
  std::ofstream(report && *report ? report : "fault_injection.txt") << figures.str();
  std::cout << figures.str();

  EXPECT_EQ(completed, accepted);
  EXPECT_EQ(mismatches, 0);
  for (int p = 0; p < kPhases; ++p) {
    EXPECT_GE(landed[p], 1) << "no kill landed during " << kPhaseNames[p];
  }
}

}  // namespace
}  // namespace boicp::test
