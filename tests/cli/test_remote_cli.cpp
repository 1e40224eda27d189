// The remote subcommands of `boicp` (submit, watch, jobs, show, cancel,
// export, health) as scripts run them, against a boicpd child process on a
// free loopback port: stdout carries only what scripts read, every error is
// one stderr line, exit codes are 0 / 1 / 2.

#include <netinet/in.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iterator>
#include <map>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <octomap/octomap.h>
#include <open3d/geometry/Image.h>
#include <open3d/io/ImageIO.h>
#include <nlohmann/json.hpp>

#include "../support/demo_sequence.hpp"
#include "../support/files_and_processes.hpp"
#include "boicp/v1/map_builder.pb.h"
#include "daemon_process.hpp"

namespace {
using boicp::test::HasStagingFile;
using boicp::test::MakeSelfSignedCertificate;
using boicp::test::RunCaptured;
using boicp::test::RunResult;
using boicp::test::Slurp;

using ::testing::ContainsRegex;
using ::testing::HasSubstr;
using ::testing::MatchesRegex;
using ::testing::Not;
namespace fs = std::filesystem;

std::vector<std::string> Lines(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream stream(text);
  for (std::string line; std::getline(stream, line);) {
    if (!line.empty()) lines.push_back(line);
  }
  return lines;
}

// A loopback port nothing listens on: bound to find it, then released.
int UnusedPort() {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  socklen_t size = sizeof address;
  ::bind(fd, reinterpret_cast<sockaddr*>(&address), sizeof address);
  ::getsockname(fd, reinterpret_cast<sockaddr*>(&address), &size);
  ::close(fd);
  return ntohs(address.sin_port);
}

fs::path SharedData(const std::string& name) { return fs::path(BOICP_SHARED_DATA_DIR) / name; }

class RemoteCli : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("boicp_remote_cli_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override {
    daemon_.reset();  // always stopped, even when an assertion failed
    fs::remove_all(dir_);
  }

  void StartDaemon(const std::vector<std::string>& extra = {}) {
    std::vector<std::string> args = {"--data-dir", (dir_ / "data").string(), "--workers", "2"};
    args.insert(args.end(), extra.begin(), extra.end());
    daemon_ = std::make_unique<boicp::test::DaemonProcess>(args, (dir_ / "daemon.log").string());
    server_ = " --server " + daemon_->address();
  }

  // `boicp <args>` through the shell, as a script runs it.
  RunResult Run(const std::string& args, const std::string& env = "") {
    return RunCaptured(env + " " + std::string(BOICP_CLI_PATH) + " " + args, dir_);
  }

  // A generated drive as a KITTI-like folder (velodyne/*.bin, no side
  // files); returns each scan's T_world_scan.
  std::vector<boicp::Transform> WriteDrive(const fs::path& root, int n, uint64_t seed) {
    const fs::path folder = root / "velodyne";
    fs::create_directories(folder);
    std::vector<boicp::Transform> truth;
    int index = 0;
    for (const auto& scan : boicp::test::MakeDemoSequence(n, seed)) {
      char name[32];
      std::snprintf(name, sizeof name, "%06d.bin", index++);
      std::ofstream(folder / name, std::ios::binary) << scan.kitti_bytes;
      truth.push_back(scan.T_world_scan);
    }
    return truth;
  }

  // submit --wait; returns the job id (stdout holds it alone).
  std::string SubmitAndWait(const std::string& args) {
    const RunResult r = Run("submit " + args + " --wait" + server_);
    EXPECT_EQ(r.exit_code, 0) << r.err << "\n" << daemon_->Log();
    EXPECT_THAT(r.out, MatchesRegex("job-[0-9]+\n")) << r.out;
    EXPECT_THAT(r.err, HasSubstr("succeeded"));
    EXPECT_THAT(r.err, ContainsRegex("[0-9]+ of [0-9]+ pairs doubtful")) << r.err;
    return Lines(r.out).empty() ? "" : Lines(r.out)[0];
  }

  // Exports bt, ot, ply, tum and kitti and checks each file and both
  // previews, and that the previews' up came from `up_prior` (the job's scan
  // format tells it).
  void ExportAndCheck(const std::string& job, size_t num_scans, const std::string& up_prior) {
    const fs::path out = dir_ / "export";
    for (const char* format : {"bt", "ot", "ply", "tum", "kitti"}) {
      const fs::path file = out / (std::string("map_") + format + "." + format);
      const RunResult r =
          Run("export " + job + " --format " + format + " -o " + file.string() + server_);
      ASSERT_EQ(r.exit_code, 0) << format << ": " << r.err;
      EXPECT_TRUE(r.out.empty()) << r.out;
      if (std::string(format) == "bt") {
        EXPECT_THAT(r.err, HasSubstr(up_prior));
      }
      ASSERT_TRUE(fs::exists(file)) << file;
      EXPECT_FALSE(HasStagingFile(out));
    }
    const std::string bt = Slurp(out / "map_bt.bt");
    EXPECT_EQ(bt.rfind("# Octomap OcTree binary file", 0), 0u);
    octomap::OcTree tree(0.1);
    ASSERT_TRUE(tree.readBinary((out / "map_bt.bt").string()));
    EXPECT_GT(tree.getNumLeafNodes(), 0u);
    std::unique_ptr<octomap::AbstractOcTree> full(
        octomap::AbstractOcTree::read((out / "map_ot.ot").string()));
    ASSERT_NE(dynamic_cast<octomap::OcTree*>(full.get()), nullptr);
    EXPECT_EQ(Slurp(out / "map_ply.ply").rfind("ply", 0), 0u);
    EXPECT_EQ(Lines(Slurp(out / "map_tum.tum")).size(), num_scans);
    const std::vector<std::string> kitti = Lines(Slurp(out / "map_kitti.kitti"));
    ASSERT_EQ(kitti.size(), num_scans);
    std::istringstream first(kitti[0]);
    std::vector<double> numbers{std::istream_iterator<double>(first),
                                std::istream_iterator<double>()};
    EXPECT_EQ(numbers.size(), 12u);
    for (const char* png : {"map_bt.png", "map_ot.png"}) {
      open3d::geometry::Image image;
      ASSERT_TRUE(open3d::io::ReadImage((out / png).string(), image)) << png;
      ASSERT_GT(image.width_ * image.height_, 0) << png;
      const std::vector<uint8_t>& pixels = image.data_;
      EXPECT_NE(std::count(pixels.begin(), pixels.end(), pixels.front()),
                static_cast<long>(pixels.size()))
          << png << " is blank";
    }
  }

  fs::path dir_;
  std::unique_ptr<boicp::test::DaemonProcess> daemon_;
  std::string server_;
};

// Quick settings for the generated drive (as the daemon's tests use).
const char* kQuick =
    " --config A --random-samples 4 --iterations 4 --rotation-bounds 0.2,0.2,3.14159";

TEST_F(RemoteCli, GeneratedDriveSubmitWaitShowJobsAndExport) {
  StartDaemon();
  const std::vector<boicp::Transform> truth = WriteDrive(dir_ / "drive", 4, 11);
  // The fixed budget reaches the daemon's job: the paper's search answers.
  const std::string job = SubmitAndWait((dir_ / "drive").string() + kQuick +
                                        " --resolution 0.3 --label drive4 --budget fixed");

  const RunResult show = Run("show " + job + " --json" + server_);
  ASSERT_EQ(show.exit_code, 0) << show.err;
  const nlohmann::json j = nlohmann::json::parse(show.out);  // throws if stdout holds more
  EXPECT_EQ(j["job_id"], job);
  EXPECT_EQ(j["state"], "succeeded");
  EXPECT_EQ(j["label"], "drive4");
  // Every field of the job under its .proto name, the defaults too; the
  // stage by its name only.
  const google::protobuf::Descriptor& job_fields = *boicp::v1::Job::descriptor();
  for (int f = 0; f < job_fields.field_count(); ++f) {
    const std::string name = job_fields.field(f)->name();
    EXPECT_EQ(j.contains(name), name != "stage_code") << name;
  }
  EXPECT_EQ(j["stage"], "done");
  EXPECT_EQ(j["pairs_done"], 3);
  EXPECT_EQ(j["error"], "");
  EXPECT_EQ(j["cancel_requested"], false);
  // The settings used, under the names run.json's "chosen" has.
  const nlohmann::json& used = j["settings"];
  EXPECT_EQ(used["preset"], "A");
  EXPECT_EQ(used["random_samples"], 4);
  EXPECT_EQ(used["rotation_bounds"], nlohmann::json({0.2, 0.2, M_PI}));
  EXPECT_EQ(used["no_retry"], false);
  EXPECT_EQ(used["budget"], "fixed");
  EXPECT_GT(used["voxel"].get<double>(), 0.0);
  EXPECT_DOUBLE_EQ(used["map_resolution"].get<double>(), 0.3);
  EXPECT_EQ(used["far_returns"], 0);  // generated scans have none
  EXPECT_EQ(used["sensor"]["type"], "lidar");
  EXPECT_THAT(used["sensor"]["why"].get<std::string>(), HasSubstr("ground plane"));
  ASSERT_EQ(j["pairs"].size(), 3u);
  ASSERT_EQ(j["trajectory"].size(), 4u);
  int doubtful = 0;
  std::map<std::string, int> rungs;  // the closing line's words
  for (const auto& pair : j["pairs"]) {
    ASSERT_TRUE(pair["doubtful"].is_boolean()) << pair.dump();
    EXPECT_EQ(pair["doubtful"].get<bool>(), pair["confidence"].get<double>() < 0.5);
    ASSERT_TRUE(pair["overlap"].is_number()) << pair.dump();
    EXPECT_GT(pair["overlap"].get<double>(), 0.0);
    ASSERT_TRUE(pair["search_reach"].is_number()) << pair.dump();
    doubtful += pair["doubtful"].get<bool>();
    EXPECT_THAT(pair["answered_by"].get<std::string>(), ::testing::AnyOf("full-search", "retry"));
    EXPECT_GT(pair["evaluations"].get<int>(), 0);
    rungs[pair["answered_by"] == "retry" ? "retry" : "full"] += 1;
  }
  EXPECT_EQ(j["pairs_doubtful"], doubtful);
  for (const auto& pair : j["pairs"]) {
    // T_target_source of consecutive scans against the generated truth.
    const int s = pair["source"], t = pair["target"];
    const boicp::Transform expected = truth[t].inverse() * truth[s];
    for (int row = 0; row < 3; ++row) {
      EXPECT_NEAR(pair["transform"][row][3].get<double>(), expected(row, 3), 0.1);
      for (int col = 0; col < 3; ++col) {
        EXPECT_NEAR(pair["transform"][row][col].get<double>(), expected(row, col), 0.02);
      }
    }
  }
  const RunResult human = Run("show " + job + server_);
  ASSERT_EQ(human.exit_code, 0) << human.err;
  EXPECT_THAT(human.out, HasSubstr("succeeded"));
  EXPECT_THAT(human.out, HasSubstr(std::to_string(doubtful) + " of 3 pairs doubtful"));
  EXPECT_THAT(human.out, HasSubstr("budget fixed"));
  EXPECT_THAT(human.out, HasSubstr("answered_by"));
  // It closes with the count per rung, in ladder order.
  std::string closing;
  for (const char* word : {"full", "retry"}) {
    if (rungs[word] == 0) continue;
    closing += (closing.empty() ? "" : ", ") + std::to_string(rungs[word]) + " " + word;
  }
  EXPECT_EQ(Lines(human.out).back(), closing) << human.out;

  // The address may come from BOICP_SERVER instead of --server.
  const RunResult jobs = Run("jobs --json", "BOICP_SERVER=" + daemon_->address());
  ASSERT_EQ(jobs.exit_code, 0) << jobs.err;
  const nlohmann::json list = nlohmann::json::parse(jobs.out);
  ASSERT_EQ(list["jobs"].size(), 1u);
  EXPECT_EQ(list["jobs"][0]["job_id"], job);
  EXPECT_EQ(list["jobs"][0]["pairs_done"], 3);
  const RunResult table = Run("jobs" + server_);
  ASSERT_EQ(table.exit_code, 0) << table.err;
  EXPECT_THAT(table.out, HasSubstr(job));
  EXPECT_THAT(table.out, HasSubstr("drive4"));

  // A second submit of the same folder sends no scan bytes again.
  const RunResult again = Run("submit " + (dir_ / "drive").string() + kQuick + server_);
  ASSERT_EQ(again.exit_code, 0) << again.err;
  EXPECT_THAT(again.err, HasSubstr("4 already on the daemon"));
  EXPECT_EQ(Lines(again.out).size(), 1u);

  ExportAndCheck(job, 4, "the sensors' up");
  // Without --format, the extension of -o names it.
  const RunResult by_name = Run("export " + job + " -o " + (dir_ / "t.tum").string() + server_);
  ASSERT_EQ(by_name.exit_code, 0) << by_name.err;
  EXPECT_EQ(Lines(Slurp(dir_ / "t.tum")).size(), 4u);
}

// --method reaches the daemon's job: with icp each neighbouring pair is one
// refinement from the identity, and the drive still comes out right.
TEST_F(RemoteCli, TheIcpMethodReachesTheDaemonsJob) {
  StartDaemon();
  const std::vector<boicp::Transform> truth = WriteDrive(dir_ / "drive", 4, 11);
  const std::string job =
      SubmitAndWait((dir_ / "drive").string() + kQuick + " --resolution 0.3 --method icp");
  const RunResult show = Run("show " + job + " --json" + server_);
  ASSERT_EQ(show.exit_code, 0) << show.err;
  const nlohmann::json j = nlohmann::json::parse(show.out);
  EXPECT_EQ(j["settings"]["method"], "icp");
  ASSERT_EQ(j["pairs"].size(), 3u);
  for (const auto& pair : j["pairs"]) {
    EXPECT_EQ(pair["answered_by"], "prior") << pair.dump();
    EXPECT_EQ(pair["evaluations"], 1);
    const int s = pair["source"], t = pair["target"];
    const boicp::Transform expected = truth[t].inverse() * truth[s];
    for (int row = 0; row < 3; ++row) {
      EXPECT_NEAR(pair["transform"][row][3].get<double>(), expected(row, 3), 0.1);
    }
  }
}

// The same folder submitted again with --poses-as-priors and a times.txt:
// the daemon holds the scans from the first submit (their first upload's
// context is only its default), and each job uses the context it sent.
TEST_F(RemoteCli, TheSameFolderSubmittedAgainWithPosesAsPriorsUsesThem) {
  StartDaemon();
  const fs::path root = dir_ / "drive";
  const std::vector<boicp::Transform> truth = WriteDrive(root, 4, 11);
  const std::string plain = SubmitAndWait(root.string() + kQuick + " --resolution 0.3");

  // KITTI side files: poses 100 m along x from the drive's (Tr = identity,
  // so the velodyne poses are the camera poses), and times.
  std::ofstream(root / "calib.txt") << "Tr: 1 0 0 0 0 1 0 0 0 0 1 0\n";
  {
    std::ofstream poses(root / "poses.txt"), times(root / "times.txt");
    poses << std::setprecision(17);
    for (size_t i = 0; i < truth.size(); ++i) {
      boicp::Transform T = truth[i];
      T(0, 3) += 100.0;
      for (int r = 0; r < 3; ++r) {
        for (int c = 0; c < 4; ++c) poses << T(r, c) << (r == 2 && c == 3 ? "\n" : " ");
      }
      times << 50 + static_cast<int>(i) << "\n";
    }
  }
  const RunResult again = Run("submit " + root.string() + kQuick +
                              " --resolution 0.3 --poses-as-priors --wait" + server_);
  ASSERT_EQ(again.exit_code, 0) << again.err << "\n" << daemon_->Log();
  EXPECT_THAT(again.err, HasSubstr("4 already on the daemon"));
  ASSERT_EQ(Lines(again.out).size(), 1u) << again.out;
  const std::string with_priors = Lines(again.out)[0];

  for (const std::string& job : {plain, with_priors}) {
    const RunResult show = Run("show " + job + " --json" + server_);
    ASSERT_EQ(show.exit_code, 0) << show.err;
    const nlohmann::json j = nlohmann::json::parse(show.out);
    ASSERT_EQ(j["trajectory"].size(), 4u) << job;
    const bool priors = job == with_priors;
    for (size_t i = 0; i < 4; ++i) {
      EXPECT_EQ(j["trajectory"][i]["timestamp"].get<double>(), (priors ? 50.0 : 0.0) + i) << job;
    }
    // The map frame is scan 0's, or its prior pose's world.
    EXPECT_NEAR(j["trajectory"][0]["pose"][0][3].get<double>(),
                priors ? truth[0](0, 3) + 100.0 : 0.0, 1e-6)
        << job;
  }
}

TEST_F(RemoteCli, CancelStopsAJobWatchExitsOneAndHealthServes) {
  StartDaemon();
  const RunResult health = Run("health" + server_);
  EXPECT_EQ(health.exit_code, 0) << health.err;
  EXPECT_EQ(health.out, "SERVING\n");

  WriteDrive(dir_ / "drive", 6, 5);
  // Five explicit pairs, one of them not consecutive; PATH after the FILE.
  std::ofstream(dir_ / "pairs.txt") << "source,target\n0,2\n1,2\n2,3\n3,4\n4,5\n";
  // Preset C with full rotation bounds: long enough to be cancelled mid-run.
  const RunResult submit = Run("submit --pairing explicit " + (dir_ / "pairs.txt").string() + " " +
                               (dir_ / "drive").string() + server_);
  ASSERT_EQ(submit.exit_code, 0) << submit.err;
  const std::string job = Lines(submit.out).at(0);
  const RunResult cancel = Run("cancel " + job + server_);
  EXPECT_EQ(cancel.exit_code, 0) << cancel.err;

  const RunResult watch = Run("watch " + job + server_);
  EXPECT_EQ(watch.exit_code, 1);
  ASSERT_FALSE(Lines(watch.err).empty());
  EXPECT_THAT(Lines(watch.err).back(),
              HasSubstr("boicp watch: error: job " + job + " was cancelled"));
  EXPECT_TRUE(watch.out.empty());

  const RunResult show = Run("show " + job + " --json" + server_);
  ASSERT_EQ(show.exit_code, 0) << show.err;
  const nlohmann::json cancelled = nlohmann::json::parse(show.out);
  EXPECT_EQ(cancelled["state"], "cancelled");
  EXPECT_EQ(cancelled["pairs_total"], 5);

  const RunResult exported = Run("export " + job + " -o " + (dir_ / "m.bt").string() + server_);
  EXPECT_EQ(exported.exit_code, 1);
  EXPECT_EQ(Lines(exported.err).size(), 1u) << exported.err;
  EXPECT_THAT(exported.err, HasSubstr("only a succeeded job"));
  EXPECT_FALSE(fs::exists(dir_ / "m.bt"));

  // A cancelled job can be deleted; then it is gone.
  const RunResult deleted = Run("delete " + job + server_);
  EXPECT_EQ(deleted.exit_code, 0) << deleted.err;
  EXPECT_THAT(deleted.err, HasSubstr("job " + job + " deleted ("));
  const RunResult gone = Run("show " + job + server_);
  EXPECT_EQ(gone.exit_code, 2);
  EXPECT_THAT(gone.err, HasSubstr("no job '" + job + "'"));
}

TEST_F(RemoteCli, UnreachableDaemonFailsWithOneLine) {
  WriteDrive(dir_ / "drive", 2, 3);
  const std::string address = "127.0.0.1:" + std::to_string(UnusedPort());
  const std::string server = " --server " + address;
  for (const std::string& args : std::vector<std::string>{
           "jobs", "health", "show job-000001", "watch job-000001", "cancel job-000001",
           "delete job-000001", "export job-000001 -o " + (dir_ / "m.bt").string(),
           "submit " + (dir_ / "drive").string()}) {
    const RunResult r = Run(args + server);
    EXPECT_NE(r.exit_code, 0) << args;
    EXPECT_EQ(Lines(r.err).size(), 1u) << args << ":\n" << r.err;
    EXPECT_THAT(r.err, HasSubstr("error: cannot reach the daemon at " + address)) << args;
    EXPECT_TRUE(r.out.empty()) << args;
  }
}

TEST_F(RemoteCli, UnknownJobAndBadInputGiveOneLineErrors) {
  StartDaemon();
  for (const std::string& args : std::vector<std::string>{
           "show job-999999", "watch job-999999", "cancel job-999999", "delete job-999999",
           "export job-999999 -o " + (dir_ / "m.bt").string()}) {
    const RunResult r = Run(args + server_);
    EXPECT_EQ(r.exit_code, 2) << args;
    EXPECT_EQ(Lines(r.err).size(), 1u) << args << ":\n" << r.err;
    EXPECT_THAT(r.err, HasSubstr("no job 'job-999999'")) << args;
  }

  // One malformed scan among good ones: refused before any upload.
  WriteDrive(dir_ / "mixed", 3, 3);
  std::ofstream(dir_ / "mixed" / "velodyne" / "000003.bin", std::ios::binary)
      << "abc";  // not 16-byte rows
  fs::create_directories(dir_ / "empty");
  WriteDrive(dir_ / "good", 3, 4);
  std::ofstream(dir_ / "pairs.txt") << "0 1\n";  // leaves scan 2 unconnected
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"submit " + (dir_ / "missing").string(), "no such folder"},
      {"submit " + (dir_ / "empty").string(), "no scans found"},
      {"submit " + (dir_ / "mixed").string(), "000003.bin"},
      {"submit " + (dir_ / "good").string() + " --pairing explicit " +
           (dir_ / "pairs.txt").string(),
       "do not connect scan 2"},
      {"submit " + (dir_ / "good").string() + " --config Z", "unknown preset 'Z'"},
      {"submit " + (dir_ / "good").string() + " --budget nope",
       "--budget: unknown budget 'nope' (expected auto or fixed)"},
      {"submit " + (dir_ / "good").string() + " --method ransac",
       "--method: unknown registration method 'ransac' (known: bo-icp, icp)"},
      {"submit " + (dir_ / "good").string() + " --rotation-bounds 1,2", "--rotation-bounds"},
      {"submit " + (dir_ / "good").string() + " --pairing sideways", "--pairing"},
      {"export job-000001 --format gif", "--format"},
  };
  for (const auto& [args, expected] : cases) {
    const RunResult r = Run(args + server_);
    EXPECT_EQ(r.exit_code, 2) << args;
    EXPECT_EQ(Lines(r.err).size(), 1u) << args << ":\n" << r.err;
    EXPECT_THAT(r.err, HasSubstr(expected)) << args;
    EXPECT_TRUE(r.out.empty()) << args;
  }
  const fs::path scans = dir_ / "data" / "scans";
  EXPECT_TRUE(!fs::exists(scans) ||
              fs::recursive_directory_iterator(scans) == fs::recursive_directory_iterator())
      << "a refused folder uploaded scans";
  const RunResult jobs = Run("jobs --json" + server_);
  EXPECT_TRUE(nlohmann::json::parse(jobs.out)["jobs"].empty());
}

// A label is whatever a client sent: printed raw, its escapes would retitle
// the window and clear the screen of whoever lists the jobs.
TEST_F(RemoteCli, ServerTextIsPrintedWithoutTerminalControls) {
  StartDaemon();
  WriteDrive(dir_ / "drive", 2, 5);
  const std::string job = SubmitAndWait((dir_ / "drive").string() + kQuick +
                                        " --label \"$(printf 'a\\033]0;owned\\007\\033[2Jb')\"");
  for (const std::string& args : {std::string("jobs"), "show " + job}) {
    const RunResult r = Run(args + server_);
    ASSERT_EQ(r.exit_code, 0) << args << "\n" << r.err;
    EXPECT_EQ(r.out.find('\x1b'), std::string::npos) << args;
    EXPECT_EQ(r.out.find('\x07'), std::string::npos) << args;
    EXPECT_THAT(r.out, HasSubstr("a\\x1b]0;owned\\x07\\x1b[2Jb")) << args;
  }
}

TEST_F(RemoteCli, TokenIsRequiredAndNeverPrinted) {
  std::ofstream(dir_ / "token") << "s3cret-token\n";
  std::ofstream(dir_ / "wrong") << "not-the-token\n";
  StartDaemon({"--auth-token-file", (dir_ / "token").string()});

  const RunResult missing = Run("jobs" + server_);
  EXPECT_NE(missing.exit_code, 0);
  EXPECT_EQ(Lines(missing.err).size(), 1u) << missing.err;
  EXPECT_THAT(missing.err, HasSubstr("--token-file"));

  // Without TLS the token goes only with --insecure.
  const RunResult plaintext = Run("jobs --token-file " + (dir_ / "token").string() + server_);
  EXPECT_EQ(plaintext.exit_code, 2);
  EXPECT_EQ(Lines(plaintext.err).size(), 1u) << plaintext.err;
  EXPECT_THAT(plaintext.err, HasSubstr("--insecure"));

  const RunResult wrong =
      Run("jobs --insecure --token-file " + (dir_ / "wrong").string() + server_);
  EXPECT_NE(wrong.exit_code, 0);
  EXPECT_EQ(Lines(wrong.err).size(), 1u) << wrong.err;
  EXPECT_THAT(wrong.err, HasSubstr("rejected the token"));
  EXPECT_THAT(wrong.err, Not(HasSubstr("not-the-token")));

  const RunResult unreadable =
      Run("jobs --insecure --token-file " + (dir_ / "nope").string() + server_);
  EXPECT_EQ(unreadable.exit_code, 2);
  EXPECT_EQ(Lines(unreadable.err).size(), 1u) << unreadable.err;

  const RunResult right =
      Run("jobs --json --insecure --token-file " + (dir_ / "token").string() + server_);
  EXPECT_EQ(right.exit_code, 0) << right.err;
  EXPECT_THAT(right.out + right.err, Not(HasSubstr("s3cret-token")));

  const RunResult health = Run("health" + server_);  // probes need no token
  EXPECT_EQ(health.exit_code, 0) << health.err;
  EXPECT_EQ(health.out, "SERVING\n");
}

TEST_F(RemoteCli, TlsNeedsTheCaFile) {
  const std::string key = (dir_ / "key.pem").string(), cert = (dir_ / "cert.pem").string();
  if (!MakeSelfSignedCertificate(key, cert)) GTEST_SKIP() << "openssl is not available";
  StartDaemon({"--tls-cert", cert, "--tls-key", key});

  const RunResult secure = Run("health --tls-ca " + cert + server_);
  EXPECT_EQ(secure.exit_code, 0) << secure.err;
  EXPECT_EQ(secure.out, "SERVING\n");
  const RunResult jobs = Run("jobs --json --tls-ca " + cert + server_);
  EXPECT_EQ(jobs.exit_code, 0) << jobs.err;

  const RunResult plaintext = Run("jobs" + server_);  // a TLS daemon refuses plaintext
  EXPECT_NE(plaintext.exit_code, 0);
  EXPECT_EQ(Lines(plaintext.err).size(), 1u) << plaintext.err;
  const RunResult no_ca = Run("jobs --tls-ca " + (dir_ / "none.pem").string() + server_);
  EXPECT_EQ(no_ca.exit_code, 2);
  EXPECT_THAT(no_ca.err, HasSubstr("--tls-ca"));
  EXPECT_EQ(Lines(no_ca.err).size(), 1u) << no_ca.err;
}

TEST_F(RemoteCli, KittiSubmitWaitAndExport) {
  const fs::path kitti = SharedData("kitti00");
  if (!fs::exists(kitti / "velodyne")) GTEST_SKIP() << "no KITTI data in " << kitti;
  StartDaemon();
  const std::string job = SubmitAndWait(kitti.string() + " --config A --count 4");
  ExportAndCheck(job, 4, "the sensors' up");
}

TEST_F(RemoteCli, SevenScenesSubmitWaitAndExport) {
  const fs::path scenes = SharedData("7scenes_redkitchen");
  if (!fs::exists(scenes / "depth")) GTEST_SKIP() << "no 7-Scenes data in " << scenes;
  StartDaemon();
  // A room wants a finer voxel and map than a street.
  const std::string job = SubmitAndWait(scenes.string() +
                                        " --config A --stride 30 --count 4 --voxel 0.05 "
                                        "--translation-bounds 0.5,0.5,0.5 --resolution 0.05");
  ExportAndCheck(job, 4, "the sensors' up");
}

}  // namespace
