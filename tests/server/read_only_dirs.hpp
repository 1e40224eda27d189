#pragma once
// Makes directories refuse new files for a while, the way a read-only mount
// or a wrong owner would, to test how the daemon copes.

#include <filesystem>
#include <string>
#include <vector>

namespace boicp::test {

/// While it lives, `dirs` refuse new entries. A regular user gets mode 0555;
/// root ignores modes, so root gets the immutable attribute instead (which
/// needs CAP_LINUX_IMMUTABLE and an ext2/3/4, XFS or Btrfs file system).
/// Restores every directory when destroyed.
class ReadOnlyDirs {
 public:
  explicit ReadOnlyDirs(const std::vector<std::filesystem::path>& dirs);
  ~ReadOnlyDirs();
  ReadOnlyDirs(const ReadOnlyDirs&) = delete;
  ReadOnlyDirs& operator=(const ReadOnlyDirs&) = delete;

  /// "chmod 0555" or "chattr +i"; empty when neither works here (nothing changed).
  const std::string& method() const { return method_; }
  /// Why it could not, when method() is empty.
  const std::string& failure() const { return failure_; }

 private:
  void Restore();

  struct Changed {
    std::filesystem::path dir;
    std::filesystem::perms perms;
  };
  std::vector<Changed> changed_;
  std::string method_, failure_;
};

}  // namespace boicp::test
