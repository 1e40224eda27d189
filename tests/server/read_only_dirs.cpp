#include "read_only_dirs.hpp"

#include <fcntl.h>
#include <linux/fs.h>
#include <sys/ioctl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

namespace boicp::test {
namespace fs = std::filesystem;
namespace {

// Sets or clears the immutable attribute; errno's text on failure.
std::string SetImmutable(const fs::path& dir, bool on) {
  const int fd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd < 0) return std::strerror(errno);
  int flags = 0;
  int rc = ::ioctl(fd, FS_IOC_GETFLAGS, &flags);
  if (rc == 0) {
    flags = on ? (flags | FS_IMMUTABLE_FL) : (flags & ~FS_IMMUTABLE_FL);
    rc = ::ioctl(fd, FS_IOC_SETFLAGS, &flags);
  }
  const int error = errno;
  ::close(fd);
  return rc == 0 ? "" : std::strerror(error);
}

}  // namespace

ReadOnlyDirs::ReadOnlyDirs(const std::vector<fs::path>& dirs) {
  const bool root = ::geteuid() == 0;
  for (const fs::path& dir : dirs) {
    const fs::perms before = fs::status(dir).permissions();
    std::string error;
    if (root) {
      error = SetImmutable(dir, true);
    } else {
      std::error_code ec;
      fs::permissions(dir,
                      fs::perms::owner_read | fs::perms::owner_exec | fs::perms::group_read |
                          fs::perms::group_exec | fs::perms::others_read | fs::perms::others_exec,
                      ec);
      error = ec ? ec.message() : "";
    }
    if (!error.empty()) {
      failure_ = (root ? "chattr +i " : "chmod 0555 ") + dir.string() + ": " + error;
      Restore();  // the directories already changed
      return;
    }
    changed_.push_back({dir, before});
  }
  method_ = root ? "chattr +i" : "chmod 0555";
}

ReadOnlyDirs::~ReadOnlyDirs() { Restore(); }

void ReadOnlyDirs::Restore() {
  const bool root = ::geteuid() == 0;
  for (const Changed& c : changed_) {
    std::error_code ignored;
    if (root) {
      SetImmutable(c.dir, false);
    } else {
      fs::permissions(c.dir, c.perms, ignored);
    }
  }
  changed_.clear();
}

}  // namespace boicp::test
