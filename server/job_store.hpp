#pragma once
// Durable state of the daemon in SQLite (WAL, synchronous=FULL): scans'
// metadata, jobs with their normalised request and a snapshot of their
// scans' metadata, finished pair results (and the rung that answered each)
// and trajectories. Every write is its own transaction, so a daemon killed
// at any moment loses nothing it acknowledged. Thread-safe: one connection
// behind a mutex.

#include <cstdint>
#include <map>
#include <mutex>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "boicp/mapping/fusion_memory.hpp"
#include "boicp/mapping/pose_graph.hpp"
#include "boicp/v1/map_builder.pb.h"
#include "sqlite_db.hpp"

namespace boicp::server {

namespace v1 = ::boicp::v1;

struct StoredScan {
  v1::ScanMetadata metadata;  // sha256 holds the scan id
  uint64_t num_points = 0;
  RangeProfile ranges;  // empty for scans stored before profiles were
};

/// What a job needs to run, as accepted at submission.
struct JobInput {
  v1::SubmitBatchRequest request;       // stored whole: its scan_context is the batch's
  std::vector<v1::ScanMetadata> scans;  // one per request.scan_ids entry, the stored records
};

struct StoredPair {
  v1::PairResult result;
  InformationMatrix information = InformationMatrix::Identity();
};

struct ResultsPage {
  std::vector<v1::PairResult> pairs;
  std::vector<v1::TrajectoryPose> poses;
  std::string next_page_token;  // empty on the last page
};

struct JobPage {
  std::vector<v1::Job> jobs;
  std::string next_page_token;
};

/// The schema version the job store writes (SQLite's user_version). A
/// database of an older version is migrated when opened; a newer one is
/// refused.
constexpr int kSchemaVersion = 1;

class JobStore {
 public:
  /// Opens or creates the database and its schema, migrating an older
  /// schema version. Throws std::runtime_error, also for a database of a
  /// schema version newer than kSchemaVersion.
  explicit JobStore(const std::string& path);

  /// Stores a scan's record unless it has one, and returns the record as
  /// stored. The first upload's metadata (its context too, the default for
  /// batches that send none) and point count stay for good (see
  /// scan_metadata_once.hpp); a later call only fills in the range profile of
  /// a record stored without one, when its metadata is the same.
  StoredScan PutScan(const v1::ScanMetadata& metadata, uint64_t num_points,
                     const RangeProfile& ranges);
  std::optional<StoredScan> GetScan(const std::string& scan_id);

  /// Assigns the job id ("job-000001", ...) and stores the job and its
  /// input in one transaction. Returns the job with its id set.
  v1::Job CreateJob(v1::Job job, const JobInput& input);
  /// Stores `job` unless the stored job is already final (succeeded, failed,
  /// cancelled): a final state is never overwritten, and a stored
  /// cancel_requested stays set. Returns whether `job` was stored.
  bool UpdateJob(const v1::Job& job);
  /// Marks an unfinished job cancel-requested in one step. Returns the job
  /// as stored afterwards (unchanged when already final), nullopt if unknown.
  std::optional<v1::Job> RequestCancel(const std::string& job_id);
  std::optional<v1::Job> GetJob(const std::string& job_id);
  /// Deletes a final job's rows (job, scans list, pairs, trajectory) in one
  /// transaction. Returns the job as it was, nullopt when unknown; an
  /// unfinished job is returned and kept.
  std::optional<v1::Job> DeleteFinishedJob(const std::string& job_id);
  /// Every job id the store holds.
  std::set<std::string> JobIds();
  /// The ids of the scans some stored job uses.
  std::set<std::string> ScansInUse();
  /// Forgets a scan's metadata (its file is the DataDir's).
  void DeleteScan(const std::string& scan_id);
  /// The final jobs whose finished_at (seconds since the epoch) is before `cutoff`.
  std::vector<std::string> JobsFinishedBefore(double cutoff);
  std::optional<JobInput> GetJobInput(const std::string& job_id);
  /// Newest first. `page_token` is opaque (empty = first page); throws
  /// InputError for a token this store did not hand out.
  JobPage ListJobs(int page_size, const std::string& page_token);
  /// Queued and running jobs, oldest first: the work a restarted daemon resumes.
  std::vector<v1::Job> UnfinishedJobs();

  /// Counts a daemon starting to run the job; returns the runs begun since
  /// the last one that ended (so 2 means the previous daemon died running it).
  int BeginRun(const std::string& job_id);
  /// The run ended, by any outcome, with the daemon alive.
  void EndRun(const std::string& job_id);
  /// Runs begun and never ended: each one is a daemon that died running the job.
  int UnendedRuns(const std::string& job_id);

  /// Stores one finished pair (replacing an earlier result for the same pair).
  void PutPair(const std::string& job_id, int plan_order, const v1::PairResult& result,
               const InformationMatrix& information);
  /// In plan order.
  std::vector<StoredPair> GetPairs(const std::string& job_id);
  /// Sets in_graph on every stored pair of the job: true exactly for `in_graph`.
  void MarkPairsInGraph(const std::string& job_id, const std::vector<PairIndex>& in_graph,
                        const std::map<PairIndex, std::string>& left_out = {});

  void PutTrajectory(const std::string& job_id, const std::vector<v1::TrajectoryPose>& poses);
  /// Up to `page_size` (>= 1) pairs, in plan order, and up to as many poses,
  /// after where `page_token` (empty = the start) says the previous page
  /// ended. Throws InputError on a token no page gave.
  ResultsPage GetResultsPage(const std::string& job_id, int page_size,
                             const std::string& page_token);

  /// Moves the WAL into the main file (on a clean shutdown).
  void Checkpoint();

 private:
  /// Adds `column` (its SQL `definition`) to `table` unless it is there:
  /// databases written before it existed open with its default.
  // Brings a database of an older schema version to kSchemaVersion, in one
  // transaction; refuses one of a newer version.
  void Migrate();
  void AddMissingColumn(const std::string& table, const std::string& column,
                        const std::string& definition);
  int ReadUnendedRuns(const std::string& job_id);
  /// GetScan with mutex_ already held.
  std::optional<StoredScan> ReadScan(const std::string& scan_id);
  std::optional<v1::Job> ReadJob(const std::string& job_id);
  void WriteJob(const v1::Job& job);
  std::vector<StoredPair> ReadPairs(const std::string& job_id);
  /// Runs `work` holding mutex_, with SQLite's failures as
  /// RethrowSqliteError throws them.
  template <typename Work>
  auto Locked(Work&& work) -> decltype(work());

  std::mutex mutex_;
  SQLite::Database db_;
};

}  // namespace boicp::server
