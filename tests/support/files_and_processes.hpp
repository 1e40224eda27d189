#pragma once
// Helpers the test suites share: a scratch folder per test, reading a file
// whole, spotting staging files an atomic write left behind, and running a
// command as a script would, with its output captured. Header-only, so every
// test target can include it.

#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include <gtest/gtest.h>

namespace boicp::test {

/// A new folder under the system's temporary directory, named after the
/// running test and this process, and removed with its contents when the
/// object goes.
class ScratchDir {
 public:
  explicit ScratchDir(const std::string& prefix) {
    std::string test = ::testing::UnitTest::GetInstance()->current_test_info()->name();
    for (char& c : test) {
      if (c == '/') c = '_';  // a parameterised test's name
    }
    path_ = std::filesystem::temp_directory_path() /
            (prefix + "_" + std::to_string(::getpid()) + "_" + test);
    std::filesystem::remove_all(path_);
    std::filesystem::create_directories(path_);
  }
  ~ScratchDir() {
    std::error_code ignored;
    std::filesystem::remove_all(path_, ignored);
  }
  ScratchDir(const ScratchDir&) = delete;
  ScratchDir& operator=(const ScratchDir&) = delete;
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

inline std::string Slurp(const std::filesystem::path& path) {
  std::ifstream file(path);
  return {std::istreambuf_iterator<char>(file), std::istreambuf_iterator<char>()};
}

/// True when `dir` holds a staging file ("*.tmp") left by an atomic write.
inline bool HasStagingFile(const std::filesystem::path& dir) {
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    if (entry.path().extension() == ".tmp") return true;
  }
  return false;
}

struct RunResult {
  int exit_code = -1;  // -1 when the command did not exit normally
  std::string out, err;
};

/// Runs `command` through the shell with stdout and stderr redirected to
/// files in `scratch_dir` (which must exist), and returns both.
inline RunResult RunCaptured(const std::string& command, const std::filesystem::path& scratch_dir) {
  const std::filesystem::path out = scratch_dir / "stdout", err = scratch_dir / "stderr";
  const int status = std::system((command + " >" + out.string() + " 2>" + err.string()).c_str());
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, Slurp(out), Slurp(err)};
}

/// Writes a one-day self-signed certificate for localhost and 127.0.0.1 to
/// `cert_path`, and its key to `key_path`, with openssl. False when openssl
/// is not available or fails.
inline bool MakeSelfSignedCertificate(const std::string& key_path, const std::string& cert_path) {
  const std::string command =
      "openssl req -x509 -newkey rsa:2048 -nodes -days 1 -subj /CN=localhost "
      "-addext subjectAltName=DNS:localhost,IP:127.0.0.1 -keyout " +
      key_path + " -out " + cert_path + " >/dev/null 2>&1";
  return std::system(command.c_str()) == 0;
}

}  // namespace boicp::test
