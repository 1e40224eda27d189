#include "atomic_file.hpp"

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <system_error>

#include "boicp/types.hpp"

namespace boicp::bench {

void WriteFileAtomically(const std::string& path, const std::string& text) {
  // The pid keeps two benches writing into one folder from sharing a temp file.
  const std::string temp = path + ".tmp." + std::to_string(::getpid());
  {
    std::ofstream file(temp, std::ios::binary | std::ios::trunc);
    if (!file) throw InputError(temp + ": cannot write");
    file << text;
    file.flush();
    if (!file) throw InputError(temp + ": write failed");
  }
  std::error_code error;
  std::filesystem::rename(temp, path, error);
  if (error) {
    std::filesystem::remove(temp, error);
    throw InputError(path + ": cannot replace (" + error.message() + ")");
  }
}

}  // namespace boicp::bench
