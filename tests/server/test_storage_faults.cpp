// The data directory failing under the daemon: unusable or too full at start
// (one clear line, exit 1), unwritable or nearly full while running
// (FAILED_PRECONDITION for uploads and batches, and service again once it is
// fixed, with nothing lost), and a scan corrupted on disk (found by its
// SHA-256: its job fails naming it, and the client can send it again).

#include <fcntl.h>
#include <linux/magic.h>
#include <signal.h>
#include <sqlite3.h>
#include <sys/statfs.h>
#include <sys/statvfs.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <fstream>
#include <thread>

#include <gmock/gmock.h>

#include "../support/demo_sequence.hpp"
#include "../support/files_and_processes.hpp"
#include "read_only_dirs.hpp"
#include "server_fixture.hpp"

namespace boicp::test {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;
using ::testing::Not;
using Code = grpc::StatusCode;

constexpr uint64_t kMiB = 1 << 20;

uint64_t FreeBytes(const fs::path& path) {
  struct statvfs info {};
  if (::statvfs(path.c_str(), &info) != 0) return 0;
  return static_cast<uint64_t>(info.f_bavail) * info.f_frsize;
}

// One byte in the middle of the file, flipped in place.
void FlipAByte(const fs::path& file) {
  std::fstream stream(file, std::ios::in | std::ios::out | std::ios::binary);
  ASSERT_TRUE(stream) << file;
  stream.seekg(0, std::ios::end);
  const std::streamoff middle = stream.tellg() / 2;
  char byte = 0;
  stream.seekg(middle);
  stream.get(byte);
  stream.seekp(middle);
  stream.put(static_cast<char>(byte ^ 0x5a));
}

// Runs `sql` on the daemon's database through a second connection, the way
// a failing disk would reach the daemon: through its own statements.
void ExecOnDatabase(const fs::path& database, const std::string& sql) {
  sqlite3* db = nullptr;
  ASSERT_EQ(sqlite3_open(database.c_str(), &db), SQLITE_OK);
  sqlite3_busy_timeout(db, 10000);
  char* error = nullptr;
  const int code = sqlite3_exec(db, sql.c_str(), nullptr, nullptr, &error);
  EXPECT_EQ(code, SQLITE_OK) << (error ? error : "");
  sqlite3_free(error);
  sqlite3_close(db);
}

class StorageFaults : public ServerTest {
 protected:
  // Every update of the jobs table matching `when` (SQL over OLD and NEW)
  // fails, as on a failing disk, until RemoveJobUpdateFault.
  void InjectJobUpdateFault(const std::string& when) const {
    ExecOnDatabase(data_dir_ / "boicpd.sqlite",
                   "CREATE TRIGGER injected_fault BEFORE UPDATE ON jobs WHEN " + when +
                       " BEGIN SELECT RAISE(ABORT, 'injected storage fault'); END");
  }
  void RemoveJobUpdateFault() const {
    ExecOnDatabase(data_dir_ / "boicpd.sqlite", "DROP TRIGGER injected_fault");
  }

  fs::path ScanFile(const std::string& id) const {
    return data_dir_ / "scans" / id.substr(0, 2) / id;
  }

  std::vector<fs::path> DataDirs() const {
    return {data_dir_, data_dir_ / "scans", data_dir_ / "jobs", data_dir_ / "tmp"};
  }

  // boicpd must refuse to start: exit 1 with exactly one line, containing each of `expected`.
  void ExpectStartRefused(const std::string& args, const std::vector<std::string>& expected) {
    const RunResult run = RunCaptured(
        std::string("timeout 60 ") + BOICPD_PATH + " --listen 127.0.0.1:0 " + args, dir_);
    const std::string output = run.out + run.err;
    EXPECT_EQ(run.exit_code, 1) << output;
    EXPECT_EQ(std::count(output.begin(), output.end(), '\n'), 1) << output;
    for (const std::string& text : expected) EXPECT_THAT(output, HasSubstr(text));
  }

  // A scan this test has not uploaded before.
  static std::string FreshScan(int seed) {
    return test::MakeDemoSequence(1, 1000 + static_cast<uint64_t>(seed))[0].kitti_bytes;
  }
};

TEST_F(StorageFaults, StartRefusesAnUnusableDataDirInOneLine) {
  // A path under a regular file cannot become a directory, for root too.
  std::ofstream(dir_ / "plain-file") << "not a directory\n";
  ExpectStartRefused("--data-dir " + (dir_ / "plain-file" / "data").string(),
                     {"plain-file/data: cannot create scans/ (Not a directory)"});

  // A data directory that exists but has become read-only.
  StartDaemon({"--workers", "1"});
  StopDaemon();
  const ReadOnlyDirs read_only(DataDirs());
  if (read_only.method().empty()) {
    GTEST_SKIP() << "cannot make a directory read-only here: " << read_only.failure();
  }
  ExpectStartRefused("--data-dir " + data_dir_.string(),
                     {"data directory " + data_dir_.string() + " is not writable"});
}

TEST_F(StorageFaults, StartRefusesADataDirBelowTheReserve) {
  fs::create_directories(data_dir_);
  const uint64_t reserve_mb = 2 * FreeBytes(data_dir_) / kMiB + 1024;
  ExpectStartRefused(
      "--data-dir " + data_dir_.string() + " --min-free-mb " + std::to_string(reserve_mb),
      {"is nearly full", "(--min-free-mb " + std::to_string(reserve_mb) + ")"});
}

TEST_F(StorageFaults, UnwritableWhileRunningRefusesUploadsAndBatchesThenRecovers) {
  StartDaemon({"--workers", "2"});
  auto client = Client();
  const auto ids = UploadDrive(client, 3, 21);
  {
    const ReadOnlyDirs read_only(DataDirs());
    if (read_only.method().empty()) {
      GTEST_SKIP() << "cannot make a directory read-only here: " << read_only.failure();
    }
    std::cout << "data directory made read-only with " << read_only.method() << "\n";
    grpc::Status status =
        StatusOf([&] { client.Upload(FreshScan(1), Meta(v1::SCAN_FORMAT_KITTI_BIN, 0)); });
    EXPECT_EQ(status.error_code(), Code::FAILED_PRECONDITION);
    EXPECT_THAT(status.error_message(), HasSubstr("is not writable"));
    // The client learns which folder, not where the daemon keeps its data.
    EXPECT_THAT(status.error_message(), Not(HasSubstr(data_dir_.string())));
    status = StatusOf([&] { client.Submit(QuickBatch(ids)); });
    EXPECT_EQ(status.error_code(), Code::FAILED_PRECONDITION);
    EXPECT_THAT(status.error_message(), HasSubstr("is not writable"));
    EXPECT_EQ(client.ListJobs().jobs_size(), 0) << "reads still work";
  }
  // Writable again: the same daemon takes work, and the scans stored before are intact.
  EXPECT_FALSE(client.Upload(FreshScan(1), Meta(v1::SCAN_FORMAT_KITTI_BIN, 0)).scan_id().empty());
  const v1::Job done = client.Watch(client.Submit(QuickBatch(ids)).job_id());
  EXPECT_EQ(done.state(), v1::JOB_STATE_SUCCEEDED) << done.error();
  EXPECT_EQ(daemon_->Wait(0.1), -1) << "the daemon exited";
}

// Storing a running job's progress fails after its first pair, while other
// pairs still register: the job fails naming the fault, its pair tasks stop
// before the job's state is freed (under ASan a late task is a
// use-after-free report), and the daemon serves the next job.
TEST_F(StorageFaults, StoreFailingDuringRegistrationFailsTheJobAndLeavesNoTaskBehind) {
  StartDaemon({"--workers", "2"});
  auto client = Client();
  const auto ids = UploadDrive(client, 6, 23);
  // Every progress update of a running job fails; its final state still stores.
  InjectJobUpdateFault("OLD.state = 2 AND NEW.state = 2");
  const v1::Job failed = client.Watch(client.Submit(QuickBatch(ids)).job_id());
  EXPECT_EQ(failed.state(), v1::JOB_STATE_FAILED);
  EXPECT_THAT(failed.error(), HasSubstr("injected storage fault"));
  EXPECT_EQ(client.GetJob(failed.job_id()).state(), v1::JOB_STATE_FAILED);

  RemoveJobUpdateFault();
  const v1::Job done = client.Watch(client.Submit(QuickBatch(ids)).job_id());
  EXPECT_EQ(done.state(), v1::JOB_STATE_SUCCEEDED) << done.error();
  daemon_->Signal(SIGTERM);
  EXPECT_EQ(daemon_->Wait(60), 0) << daemon_->Log();
  EXPECT_THAT(daemon_->Log(), Not(HasSubstr("Sanitizer")));
}

// Storing a job's final state fails: no one is told it succeeded (the store
// still says RUNNING), and the next daemon resumes it to a stored success.
TEST_F(StorageFaults, FinalStateThatCannotBeStoredIsNotPublished) {
  StartDaemon({"--workers", "2"});
  auto client = Client();
  const auto ids = UploadDrive(client, 3, 25);
  InjectJobUpdateFault("NEW.state = 3");  // SUCCEEDED
  const std::string job_id = client.Submit(QuickBatch(ids)).job_id();
  std::atomic<bool> watcher_saw_success{false};
  // Connected here: the main thread replaces daemon_ below.
  std::thread watcher([&, own = Client()]() mutable {
    try {
      own.Watch(job_id, [&](const v1::JobEvent& e) {
        if (e.job().state() == v1::JOB_STATE_SUCCEEDED) watcher_saw_success = true;
      });
    } catch (const rpc::RpcError&) {
      // The stream ends with this daemon.
    }
  });
  PollJob(
      client, job_id,
      [&](const v1::Job&) {
        return daemon_->Log().find("cannot record the final state") != std::string::npos;
      },
      300);
  ASSERT_THAT(daemon_->Log(), HasSubstr("cannot record the final state"));
  EXPECT_EQ(client.GetJob(job_id).state(), v1::JOB_STATE_RUNNING);
  EXPECT_EQ(client.ListJobs().jobs(0).state(), v1::JOB_STATE_RUNNING);

  RemoveJobUpdateFault();
  StartDaemon({"--workers", "2"});
  watcher.join();
  EXPECT_FALSE(watcher_saw_success) << "a watcher was told SUCCEEDED that was never stored";
  client = Client();
  const v1::Job done = client.Watch(job_id);
  EXPECT_EQ(done.state(), v1::JOB_STATE_SUCCEEDED) << done.error();
  EXPECT_EQ(client.GetJob(job_id).state(), v1::JOB_STATE_SUCCEEDED);
}

TEST_F(StorageFaults, NearlyFullWhileRunningRefusesUploadsAndBatchesThenRecovers) {
  // "Full" is free space under --min-free-mb: the reserve is set just under
  // what is free now, then a ballast file takes the margin and more.
  const uint64_t free_now = FreeBytes(dir_);
  struct statfs fs_info {};
  if (::statfs(dir_.c_str(), &fs_info) == 0 && fs_info.f_type == TMPFS_MAGIC) {
    GTEST_SKIP() << dir_ << " is on tmpfs: the ballast would take memory";
  }
  if (free_now < 3 * 1024 * kMiB) GTEST_SKIP() << "needs 3 GiB free in " << dir_;
  const uint64_t margin = 768 * kMiB;
  StartDaemon({"--workers", "1", "--min-free-mb", std::to_string((free_now - margin) / kMiB),
               "--max-scan-bytes", std::to_string(2 * free_now)});
  auto client = Client();
  const auto ids = UploadDrive(client, 3, 23);

  // An upload announcing more than fits above the reserve is refused before any byte.
  grpc::Status status = RawUpload(client, Meta(v1::SCAN_FORMAT_KITTI_BIN, free_now), {});
  EXPECT_EQ(status.error_code(), Code::FAILED_PRECONDITION);
  EXPECT_THAT(status.error_message(), HasSubstr("this upload needs"));

  const fs::path ballast = dir_ / "ballast";
  {
    const int fd = ::open(ballast.c_str(), O_WRONLY | O_CREAT | O_CLOEXEC, 0600);
    ASSERT_GE(fd, 0);
    const int rc = ::fallocate(fd, 0, 0, static_cast<off_t>(2 * margin));
    ::close(fd);
    if (rc != 0) {
      fs::remove(ballast);
      GTEST_SKIP() << "fallocate is not available here";
    }
  }
  status = StatusOf([&] { client.Upload(FreshScan(2), Meta(v1::SCAN_FORMAT_KITTI_BIN, 0)); });
  EXPECT_EQ(status.error_code(), Code::FAILED_PRECONDITION);
  EXPECT_THAT(status.error_message(), HasSubstr("is nearly full"));
  EXPECT_THAT(status.error_message(), HasSubstr("--min-free-mb"));
  status = StatusOf([&] { client.Submit(QuickBatch(ids)); });
  EXPECT_EQ(status.error_code(), Code::FAILED_PRECONDITION);
  EXPECT_THAT(status.error_message(), HasSubstr("is nearly full"));

  fs::remove(ballast);
  EXPECT_FALSE(client.Upload(FreshScan(2), Meta(v1::SCAN_FORMAT_KITTI_BIN, 0)).scan_id().empty());
  const v1::Job queued = client.Submit(QuickBatch(ids));
  EXPECT_EQ(queued.state(), v1::JOB_STATE_QUEUED);
  client.Cancel(queued.job_id());
}

TEST_F(StorageFaults, ScanCorruptedBetweenUploadAndSubmitFailsItsJobByName) {
  StartDaemon({"--workers", "2"});
  auto client = Client();
  const auto ids = UploadDrive(client, 3, 25);
  FlipAByte(ScanFile(ids[1]));

  const v1::Job failed = client.Watch(client.Submit(QuickBatch(ids)).job_id());
  EXPECT_EQ(failed.state(), v1::JOB_STATE_FAILED);
  EXPECT_THAT(failed.error(), HasSubstr("scan " + ids[1] + ": sha256 mismatch"));
  // The bad copy is set aside, so the client is asked for the bytes again.
  EXPECT_TRUE(fs::exists(ScanFile(ids[1]).string() + ".corrupt"));
  EXPECT_EQ(MissingScans(client, ids), std::vector<std::string>{ids[1]});

  EXPECT_EQ(UploadDrive(client, 3, 25), ids);
  const v1::Job done = client.Watch(client.Submit(QuickBatch(ids)).job_id());
  EXPECT_EQ(done.state(), v1::JOB_STATE_SUCCEEDED) << done.error();
}

TEST_F(StorageFaults, ScanCorruptedWhileTheDaemonWasDownFailsTheResumedJob) {
  StartDaemon({"--workers", "1"});
  auto client = Client();
  const auto ids = UploadDrive(client, 3, 27);
  const std::string job_id = client.Submit(QuickBatch(ids)).job_id();
  daemon_->Signal(SIGKILL);
  ASSERT_EQ(daemon_->Wait(10), 128 + SIGKILL);
  FlipAByte(ScanFile(ids[2]));

  StartDaemon({"--workers", "1"});
  client = Client();
  const v1::Job failed = client.Watch(job_id);
  EXPECT_EQ(failed.state(), v1::JOB_STATE_FAILED);
  EXPECT_THAT(failed.error(), HasSubstr("scan " + ids[2] + ": sha256 mismatch"));
}

TEST_F(StorageFaults, CorruptedStoredCopyIsNotReusedByAnUpload) {
  StartDaemon({"--workers", "1"});
  auto client = Client();
  const std::string first = FreshScan(3), second = FreshScan(4);
  const std::string first_id = client.Upload(first, Meta(v1::SCAN_FORMAT_KITTI_BIN, 0)).scan_id();
  const std::string second_id = client.Upload(second, Meta(v1::SCAN_FORMAT_KITTI_BIN, 0)).scan_id();
  FlipAByte(ScanFile(first_id));
  FlipAByte(ScanFile(second_id));

  // Metadata alone, naming the hash: refused, the stored copy is bad.
  v1::ScanMetadata metadata = Meta(v1::SCAN_FORMAT_KITTI_BIN, first.size());
  metadata.set_sha256(first_id);
  const grpc::Status status = RawUpload(client, metadata, {});
  EXPECT_EQ(status.error_code(), Code::DATA_LOSS);
  EXPECT_THAT(status.error_message(), HasSubstr("sha256 mismatch"));

  // The client sends the bytes after all when told so.
  const v1::UploadScanResponse again = client.Upload(second, Meta(v1::SCAN_FORMAT_KITTI_BIN, 0));
  EXPECT_EQ(again.scan_id(), second_id);
  EXPECT_FALSE(again.already_present());
  EXPECT_TRUE(MissingScans(client, {second_id}).empty());
}

}  // namespace
}  // namespace boicp::test
