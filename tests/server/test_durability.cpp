// Power loss: a rename or a new directory is durable only once its parent
// directory is synced. boicpd runs a batch under strace, and every rename
// into the data directory and every directory it creates there must be
// followed by the parent directory being opened to sync it.

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <fstream>
#include <regex>
#include <set>
#include <thread>

#include <gmock/gmock.h>

#include "../support/files_and_processes.hpp"
#include "server_fixture.hpp"

namespace boicp::test {
namespace {

namespace fs = std::filesystem;

// The paths renamed to or created, and the directories opened with
// O_DIRECTORY, in the order the trace shows them.
struct TraceEvent {
  enum Kind { kRenamedTo, kCreatedDir, kOpenedDir } kind;
  std::string path;
};

std::vector<TraceEvent> ReadTrace(const fs::path& file) {
  static const std::regex rename(R"re(rename(?:at2?)?\(.*"([^"]+)",.*"([^"]+)".*\) = 0)re");
  static const std::regex mkdir(R"re(mkdir(?:at)?\((?:AT_FDCWD, )?"([^"]+)".*\) = 0)re");
  static const std::regex open_dir(
      R"re(open(?:at)?\((?:AT_FDCWD, )?"([^"]+)",[^)]*O_DIRECTORY.*\) = \d+)re");
  std::vector<TraceEvent> events;
  std::ifstream in(file);
  std::string line;
  std::smatch m;
  while (std::getline(in, line)) {
    if (std::regex_search(line, m, rename)) {
      events.push_back({TraceEvent::kRenamedTo, m[2]});
    } else if (std::regex_search(line, m, mkdir)) {
      events.push_back({TraceEvent::kCreatedDir, m[1]});
    } else if (std::regex_search(line, m, open_dir)) {
      events.push_back({TraceEvent::kOpenedDir, fs::path(m[1].str()).lexically_normal().string()});
    }
  }
  return events;
}

class Durability : public ServerTest {};

TEST_F(Durability, EveryRenameAndNewDirectoryIsSyncedIntoItsParent) {
  if (std::system("strace -V >/dev/null 2>&1") != 0) GTEST_SKIP() << "strace is not available";
  StartDaemon({"--workers", "2"});
  const fs::path trace = dir_ / "strace.txt", attach_log = dir_ / "strace.err";
  const pid_t strace = ::fork();
  if (strace == 0) {
    const std::string pid = std::to_string(daemon_->pid());
    if (!std::freopen(attach_log.c_str(), "w", stderr)) ::_exit(127);
    ::execlp("strace", "strace", "-f", "-e",
             "trace=rename,renameat,renameat2,mkdir,mkdirat,open,openat", "-o", trace.c_str(), "-p",
             pid.c_str(), static_cast<char*>(nullptr));
    ::_exit(127);
  }
  ASSERT_GT(strace, 0);
  // strace reports each thread it attached to on stderr.
  for (int i = 0; i < 600 && Slurp(attach_log).find("attached") == std::string::npos; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  ASSERT_THAT(Slurp(attach_log), ::testing::HasSubstr("attached"));
  auto client = Client();
  const v1::Job done = client.Watch(client.Submit(QuickBatch(UploadDrive(client, 3, 61))).job_id());
  ::kill(strace, SIGINT);
  int status = 0;
  ::waitpid(strace, &status, 0);
  ASSERT_EQ(done.state(), v1::JOB_STATE_SUCCEEDED) << done.error();

  const std::string root = fs::canonical(data_dir_).string();
  const std::vector<TraceEvent> events = ReadTrace(trace);
  int checked = 0;
  for (size_t i = 0; i < events.size(); ++i) {
    if (events[i].kind == TraceEvent::kOpenedDir) continue;
    const std::string path = fs::path(events[i].path).lexically_normal().string();
    if (path.rfind(root, 0) != 0) continue;
    const std::string parent = fs::path(path).parent_path().string();
    bool synced = false;
    for (size_t k = i + 1; k < events.size() && !synced; ++k) {
      synced = events[k].kind == TraceEvent::kOpenedDir && events[k].path == parent;
    }
    ++checked;
    EXPECT_TRUE(synced) << (events[i].kind == TraceEvent::kCreatedDir ? "created " : "renamed to ")
                        << path << " without syncing " << parent;
  }
  std::cout << checked << " renames and new directories checked in the data directory\n";
  EXPECT_GE(checked, 8) << "the trace saw too little: " << Slurp(attach_log);
}

}  // namespace
}  // namespace boicp::test
