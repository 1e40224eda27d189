#include "boicp/io/bag_reader.hpp"

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <fstream>

#include "bag_readers.hpp"
#include "boicp/util/text.hpp"
#include "boicp/util/types.hpp"

namespace boicp {
namespace {

namespace fs = std::filesystem;

std::string LowerExtension(const fs::path& path) { return LowerCase(path.extension().string()); }

// The storage plugin a ROS 2 bag folder names ("sqlite3", "mcap"), or empty.
std::string StorageIdentifier(const fs::path& metadata) {
  std::ifstream in(metadata);
  std::string line;
  const std::string key = "storage_identifier:";
  while (std::getline(in, line)) {
    const size_t at = line.find(key);
    if (at == std::string::npos) continue;
    std::string value = line.substr(at + key.size());
    value.erase(std::remove_if(value.begin(), value.end(),
                               [](char c) {
                                 return std::isspace(static_cast<unsigned char>(c)) || c == '"' ||
                                        c == '\'';
                               }),
                value.end());
    return value;
  }
  return "";
}

// The storage files of a ROS 2 bag folder, with the extension its metadata
// names, in rosbag2's order (NAME_0, NAME_1, ..., NAME_10: shorter names first).
std::vector<fs::path> FolderStorageFiles(const fs::path& folder) {
  const std::string identifier = StorageIdentifier(folder / "metadata.yaml");
  std::string extension;
  if (identifier == "sqlite3") extension = ".db3";
  if (identifier == "mcap") extension = ".mcap";
  if (extension.empty()) {
    throw InputError(folder.string() + ": metadata.yaml names storage '" + identifier +
                     "'; boicp reads sqlite3 and mcap bags");
  }
  std::vector<fs::path> files;
  for (const auto& entry : fs::directory_iterator(folder)) {
    if (entry.is_regular_file() && LowerExtension(entry.path()) == extension) {
      files.push_back(entry.path());
    }
  }
  if (files.empty())
    throw InputError(folder.string() + ": no " + extension + " file beside metadata.yaml");
  std::sort(files.begin(), files.end(), [](const fs::path& a, const fs::path& b) {
    const std::string x = a.filename().string(), y = b.filename().string();
    return std::make_pair(x.size(), x) < std::make_pair(y.size(), y);
  });
  return files;
}

std::unique_ptr<BagReader> OpenStorageFile(const fs::path& file, const BagLimits& limits) {
  std::error_code error;
  if (!fs::exists(file, error)) throw InputError(file.string() + ": no such file");
  const std::string ext = LowerExtension(file);
  if (ext == ".bag") return io_detail::OpenRos1Bag(file.string(), limits);
  if (ext == ".db3") return io_detail::OpenRos2SqliteBag(file.string(), limits);
  if (ext == ".mcap") return io_detail::OpenMcapBag(file.string(), limits);
  throw InputError(file.string() + ": not a bag (.bag, .db3, .mcap, or a ROS 2 bag folder)");
}

}  // namespace

std::string BagStorageName(BagStorage storage) {
  switch (storage) {
    case BagStorage::kRos1:
      return "ROS 1 bag";
    case BagStorage::kRos2Sqlite:
      return "ROS 2 bag (.db3)";
    case BagStorage::kMcap:
      return "ROS 2 bag (.mcap)";
  }
  return "bag";
}

bool IsBagPath(const std::string& path) {
  std::error_code error;
  if (fs::is_directory(path, error))
    return fs::is_regular_file(fs::path(path) / "metadata.yaml", error);
  const std::string ext = LowerExtension(path);
  return ext == ".bag" || ext == ".mcap" || ext == ".db3";
}

std::unique_ptr<BagReader> OpenBag(const std::string& path, const BagLimits& limits) {
  std::error_code error;
  if (!fs::is_directory(path, error)) return OpenStorageFile(path, limits);
  if (!fs::is_regular_file(fs::path(path) / "metadata.yaml", error)) {
    throw InputError(path + ": a folder without metadata.yaml is not a ROS 2 bag");
  }
  const std::vector<fs::path> files = FolderStorageFiles(path);
  if (files.size() == 1) return OpenStorageFile(files.front(), limits);
  std::vector<std::unique_ptr<BagReader>> parts;
  for (const fs::path& file : files) parts.push_back(OpenStorageFile(file, limits));
  return io_detail::OpenSplitBag(path, std::move(parts));
}

}  // namespace boicp
