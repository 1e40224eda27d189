#include "pair_file_store.hpp"

#include <cstdio>
#include <filesystem>
#include <utility>

namespace boicp::cli {
namespace {

namespace fs = std::filesystem;

// "000003-000004.json" -> {3, 4}; nullopt for any other name (staging files included).
std::optional<PairIndex> PairOfFileName(const std::string& name) {
  int source = -1, target = -1;
  char rest[8] = {};
  if (std::sscanf(name.c_str(), "%6d-%6d.%5s", &source, &target, rest) != 3 ||
      std::string(rest) != "json" || name.size() != 18) {
    return std::nullopt;
  }
  return PairIndex{source, target};
}

}  // namespace

PairFileStore::PairFileStore(const std::vector<ScanSource>& scans, const BoIcpConfig& config,
                             std::string out_dir)
    : scans_(scans), config_(config), out_dir_(std::move(out_dir)) {}

std::vector<PairResult> PairFileStore::LoadFinished() {
  std::vector<PairResult> finished;
  const fs::path dir = fs::path(out_dir_) / "pairs";
  std::error_code error;
  if (!fs::is_directory(dir, error)) return finished;
  const int n = static_cast<int>(scans_.size());
  for (const fs::directory_entry& entry : fs::directory_iterator(dir)) {
    const std::optional<PairIndex> pair = PairOfFileName(entry.path().filename().string());
    if (!pair || pair->source >= n || pair->target >= n || pair->source == pair->target) continue;
    std::optional<PairFile> file;
    try {
      file = ReadPairFile(out_dir_, *pair);
    } catch (const NewerPairFileError&) {
      throw;  // a newer boicp's answer: not ours to overwrite
    } catch (const InputError&) {
      continue;  // unreadable: registered again and overwritten
    }
    if (!file || file->settings != PairSettings(scans_, *pair, config_)) continue;
    finished.push_back(std::move(file->result));
  }
  return finished;
}

void PairFileStore::Save(int /*listing_order*/, const PairResult& result) {
  WritePairFile(out_dir_, scans_, result, PairSettings(scans_, result.pair, config_));
}

// pairs.json carries in_graph; the pair files themselves do not.
void PairFileStore::MarkInGraph(const std::vector<PairIndex>& /*in_graph*/,
                                const std::map<PairIndex, std::string>& /*left_out*/) {}

}  // namespace boicp::cli
