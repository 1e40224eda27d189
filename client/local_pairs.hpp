#pragma once
// Per-pair result files of a local map run: OUTDIR/pairs/SSSSSS-TTTTTT.json,
// written atomically as each pair finishes. A rerun, a shard or `boicp
// merge` reuses a file only when its settings match the run's exactly.

#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "boicp/mapping/batch_pair.hpp"

namespace boicp::cli {

/// One registered pair as stored on disk and listed in pairs.json.
struct PairRecord {
  PairIndex pair;
  std::string source_path, target_path;
  Transform transform = Transform::Identity();  // T_target_source
  double objective = 0.0, fitness = 0.0, inlier_rmse = 0.0, confidence = 0.0;
  /// Fraction of the source the target sees (RegistrationResult::overlap);
  /// nullopt in files written before it was computed.
  std::optional<double> overlap;
  /// RegistrationResult::search_reach; nullopt in files written before it
  /// was computed.
  std::optional<double> search_reach;
  /// confidence < kDoubtfulBelow; nullopt in files written before confidence
  /// was calibrated, which count as trusted.
  std::optional<bool> doubtful;
  /// The rung whose answer was kept; files written before it was recorded
  /// read as the full search, which every answer then was.
  Rung answered_by = Rung::kFullSearch;
  int evaluations = 0;  // ICP runs of every rung together
  double runtime_s = 0.0;
  uint64_t seed = 0;  // the pair's own seed
  InformationMatrix information = InformationMatrix::Identity();
  nlohmann::json settings;  // what the result depends on (PairSettings)
};

/// Everything a pair's result depends on: the job config (seed included,
/// thread count excluded) and each scan's path, load options and prior.
nlohmann::json PairSettings(const std::vector<ScanSource>& scans, const PairIndex& pair,
                            const BoIcpConfig& config);

PairRecord MakePairRecord(const std::vector<ScanSource>& scans, const PairIndex& pair,
                          const BatchPairResult& result, nlohmann::json settings);

/// The format every pair file is written in ("format"); files without one
/// are read through a migration (ReadPairFile).
constexpr int kPairFileFormat = 1;

/// A pair file of a format newer than kPairFileFormat: kept, never
/// overwritten, and reported.
class NewerPairFileError : public InputError {
 public:
  using InputError::InputError;
};

/// "OUTDIR/pairs/000003-000004.json".
std::string PairFilePath(const std::string& out_dir, const PairIndex& pair);

/// Writes the record to its file atomically (creating OUTDIR/pairs).
void WritePairFile(const std::string& out_dir, const PairRecord& record);

/// The stored record, or nullopt when there is no file. Throws InputError
/// naming the file when it exists but does not parse, and
/// NewerPairFileError when it is of a format newer than kPairFileFormat. Files without a format are
/// migrated as they are read: those written before the budget existed ran the full search, so their
/// config reads as budget "fixed" and their answer as the full search's; keys they lack read as
/// unknown.
std::optional<PairRecord> ReadPairFile(const std::string& out_dir, const PairIndex& pair);

/// The JSON of pairs.json entries: source, target, source_path,
/// target_path, transform (4x4 row-major), objective, fitness, inlier_rmse,
/// confidence, doubtful, overlap and search_reach (null when unknown),
/// answered_by (RungName), evaluations, runtime_s, seed.
nlohmann::json PairRecordToJson(const PairRecord& record);

/// Whether the record is marked doubtful (unmarked old files: no).
bool IsDoubtful(const PairRecord& record);

/// The overlap estimate the keyframe planner uses: the overlap, or the
/// fitness for files written before overlap was computed.
double PlannerOverlap(const PairRecord& record);

/// The record as a pose-graph edge, weighted by its confidence (unmarked old
/// files: fully trusted).
PairConstraint RecordConstraint(const PairRecord& record);

}  // namespace boicp::cli
