#pragma once
// Per-pair result files of a local map run: OUTDIR/pairs/SSSSSS-TTTTTT.json,
// written atomically as each pair finishes. A rerun, a shard or `boicp
// merge` reuses a file only when its settings match the run's exactly.

#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "boicp/mapping/batch_pair.hpp"
#include "boicp/mapping/pair_result.hpp"

namespace boicp::cli {

/// Everything a pair's result depends on: the job config (seed included,
/// thread count excluded) and each scan's path, load options and prior.
nlohmann::json PairSettings(const std::vector<ScanSource>& scans, const PairIndex& pair,
                            const BoIcpConfig& config);

/// The format every pair file is written in ("format"); files without one
/// are read through a migration (ReadPairFile).
constexpr int kPairFileFormat = 2;

/// A pair file of a format newer than kPairFileFormat: kept, never
/// overwritten, and reported.
class NewerPairFileError : public InputError {
 public:
  using InputError::InputError;
};

/// "OUTDIR/pairs/000003-000004.json".
std::string PairFilePath(const std::string& out_dir, const PairIndex& pair);

/// A pair file: the result and what it depends on.
struct PairFile {
  PairResult result;
  nlohmann::json settings;  // PairSettings of the run that registered it
};

/// Writes `result` and its `settings` (PairSettings) to the pair's file
/// atomically, creating OUTDIR/pairs. The file also names the two scans'
/// paths, for whoever reads it.
void WritePairFile(const std::string& out_dir, const std::vector<ScanSource>& scans,
                   const PairResult& result, const nlohmann::json& settings);

/// The stored file, or nullopt when there is none. Throws InputError naming
/// the file when it exists but does not parse, and NewerPairFileError when
/// it is of a format newer than kPairFileFormat. Files without a format are
/// migrated as they are read: those written before the budget existed ran
/// the full search, so their config reads as budget "fixed" and their
/// answer as the full search's; those written before confidence was
/// calibrated read as trusted (PairResult::confidence); other keys they
/// lack read as unknown.
std::optional<PairFile> ReadPairFile(const std::string& out_dir, const PairIndex& pair);

/// A pairs.json entry: the result's kPairListing fields and its scans' paths
/// (source_path, target_path).
nlohmann::json PairListingJson(const std::vector<ScanSource>& scans, const PairResult& result);

}  // namespace boicp::cli
