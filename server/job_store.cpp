#include "job_store.hpp"

#include <cstdio>
#include <cstring>
#include <set>

#include "boicp/rpc/proto_convert.hpp"
#include "boicp/util/types.hpp"

namespace boicp::server {
namespace {

constexpr const char* kSchema = R"sql(
CREATE TABLE IF NOT EXISTS scans (
  scan_id TEXT PRIMARY KEY,
  num_points INTEGER NOT NULL,
  metadata BLOB NOT NULL
);
CREATE TABLE IF NOT EXISTS jobs (
  seq INTEGER PRIMARY KEY,
  job_id TEXT NOT NULL UNIQUE,
  state INTEGER NOT NULL,
  job BLOB NOT NULL,
  request BLOB NOT NULL
);
CREATE INDEX IF NOT EXISTS jobs_state ON jobs (state);
CREATE TABLE IF NOT EXISTS job_scans (
  job_id TEXT NOT NULL,
  idx INTEGER NOT NULL,
  metadata BLOB NOT NULL,
  PRIMARY KEY (job_id, idx)
);
CREATE TABLE IF NOT EXISTS pair_results (
  job_id TEXT NOT NULL,
  source INTEGER NOT NULL,
  target INTEGER NOT NULL,
  plan_order INTEGER NOT NULL,
  result BLOB NOT NULL,
  information BLOB NOT NULL,
  PRIMARY KEY (job_id, source, target)
);
CREATE TABLE IF NOT EXISTS trajectories (
  job_id TEXT NOT NULL,
  idx INTEGER NOT NULL,
  pose BLOB NOT NULL,
  PRIMARY KEY (job_id, idx)
);
)sql";

std::string Serialize(const google::protobuf::MessageLite& message) {
  std::string bytes;
  if (!message.SerializeToString(&bytes)) throw std::runtime_error("protobuf: serialize failed");
  return bytes;
}

template <typename Message>
Message Parse(const std::string& bytes, const char* what) {
  Message message;
  if (!message.ParseFromString(bytes)) {
    throw std::runtime_error(std::string("data store: corrupt ") + what + " record");
  }
  return message;
}

// Jobs stored before stage_code existed carry only the stage's name.
v1::Job ParseJob(const std::string& bytes) {
  v1::Job job = Parse<v1::Job>(bytes, "job");
  if (job.stage_code() == v1::JOB_STAGE_UNSPECIFIED) {
    job.set_stage_code(rpc::JobStageFromName(job.stage()));
  }
  return job;
}

std::string InformationBytes(const InformationMatrix& information) {
  std::string bytes(sizeof(double) * 36, '\0');
  std::memcpy(bytes.data(), information.data(), bytes.size());
  return bytes;
}

InformationMatrix InformationFromBytes(const std::string& bytes) {
  InformationMatrix information = InformationMatrix::Identity();
  if (bytes.size() == sizeof(double) * 36)
    std::memcpy(information.data(), bytes.data(), bytes.size());
  return information;
}

// A range profile as bytes: its bin count, its three count arrays and the
// farthest range, in native byte order like the information matrices.
std::string RangeProfileBytes(const RangeProfile& profile) {
  if (profile.empty()) return {};
  const uint32_t bins = static_cast<uint32_t>(profile.counts.size());
  std::string bytes(reinterpret_cast<const char*>(&bins), sizeof(bins));
  for (const std::vector<uint32_t>* counts :
       {&profile.counts, &profile.ray_counts, &profile.direction_counts}) {
    bytes.append(reinterpret_cast<const char*>(counts->data()), bins * sizeof(uint32_t));
  }
  bytes.append(reinterpret_cast<const char*>(&profile.max_range), sizeof(double));
  return bytes;
}

// An empty profile for bytes that do not hold one (scans stored before
// profiles were).
RangeProfile RangeProfileFromBytes(const std::string& bytes) {
  uint32_t bins = 0;
  if (bytes.size() < sizeof(bins)) return {};
  std::memcpy(&bins, bytes.data(), sizeof(bins));
  const size_t array_bytes = size_t{bins} * sizeof(uint32_t);
  if (bins == 0 || bytes.size() != sizeof(bins) + 3 * array_bytes + sizeof(double)) return {};
  RangeProfile profile;
  const char* in = bytes.data() + sizeof(bins);
  for (std::vector<uint32_t>* counts :
       {&profile.counts, &profile.ray_counts, &profile.direction_counts}) {
    counts->resize(bins);
    std::memcpy(counts->data(), in, array_bytes);
    in += array_bytes;
  }
  std::memcpy(&profile.max_range, in, sizeof(double));
  return profile;
}

std::string JobIdForSeq(int64_t seq) {
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), "job-%06lld", static_cast<long long>(seq));
  return buffer;
}

}  // namespace

JobStore::JobStore(const std::string& path) : db_(OpenDatabase(path)) {
  Locked([&] {
    // WAL lets readers run beside the writer; FULL syncs every commit, so an
    // acknowledged upload or finished pair survives even a power cut.
    db_.exec("PRAGMA journal_mode=WAL");
    db_.exec("PRAGMA synchronous=FULL");
    db_.exec("PRAGMA foreign_keys=ON");
    db_.exec(kSchema);
    Migrate();
  });
}

template <typename Work>
auto JobStore::Locked(Work&& work) -> decltype(work()) {
  std::lock_guard<std::mutex> lock(mutex_);
  try {
    return work();
  } catch (const SQLite::Exception& e) {
    RethrowSqliteError(e);
  }
}

void JobStore::Migrate() {
  const int64_t version = db_.execAndGet("PRAGMA user_version").getInt64();
  if (version > kSchemaVersion) {
    throw std::runtime_error("data store: its schema version " + std::to_string(version) +
                             " is newer than this boicpd reads (" + std::to_string(kSchemaVersion) +
                             "); run the boicpd that wrote it, or use another --data-dir");
  }
  if (version == kSchemaVersion) return;
  SQLite::Transaction transaction(db_, SQLite::TransactionBehavior::IMMEDIATE);
  // Version 0: databases from before the version was recorded, which may
  // lack the columns added since the first release. Older rows read their
  // defaults: no unended runs, answered by the full search, as every pair
  // was before the escalation ladder, and no range profile.
  AddMissingColumn("jobs", "unended_runs", "INTEGER NOT NULL DEFAULT 0");
  AddMissingColumn("pair_results", "answered_by", "TEXT NOT NULL DEFAULT 'full-search'");
  AddMissingColumn("scans", "range_profile", "BLOB NOT NULL DEFAULT x''");
  db_.exec("PRAGMA user_version = " + std::to_string(kSchemaVersion));
  transaction.commit();
}

void JobStore::AddMissingColumn(const std::string& table, const std::string& column,
                                const std::string& definition) {
  auto columns = Query(db_, "SELECT name FROM pragma_table_info(?1)", table);
  while (columns.executeStep()) {
    if (columns.getColumn(0).getString() == column) return;
  }
  db_.exec("ALTER TABLE " + table + " ADD COLUMN " + column + " " + definition);
}

int JobStore::BeginRun(const std::string& job_id) {
  return Locked([&] {
    Run(db_, "UPDATE jobs SET unended_runs = unended_runs + 1 WHERE job_id = ?1", job_id);
    return ReadUnendedRuns(job_id);
  });
}

void JobStore::EndRun(const std::string& job_id) {
  Locked([&] { Run(db_, "UPDATE jobs SET unended_runs = 0 WHERE job_id = ?1", job_id); });
}

int JobStore::UnendedRuns(const std::string& job_id) {
  return Locked([&] { return ReadUnendedRuns(job_id); });
}

int JobStore::ReadUnendedRuns(const std::string& job_id) {
  auto stmt = Query(db_, "SELECT unended_runs FROM jobs WHERE job_id = ?1", job_id);
  return stmt.executeStep() ? stmt.getColumn(0).getInt() : 0;
}

StoredScan JobStore::PutScan(const v1::ScanMetadata& metadata, uint64_t num_points,
                             const RangeProfile& ranges) {
  return Locked([&] {
    // An existing record is kept: of two first uploads racing, the second
    // finds the first's record and is answered with it.
    Run(db_,
        "INSERT INTO scans (scan_id, num_points, metadata, range_profile) "
        "VALUES (?1, ?2, ?3, ?4) "
        "ON CONFLICT (scan_id) DO UPDATE SET range_profile = ?4 "
        "WHERE length(scans.range_profile) = 0 AND scans.metadata = ?3",
        metadata.sha256(), static_cast<int64_t>(num_points), Blob{Serialize(metadata)},
        Blob{RangeProfileBytes(ranges)});
    return *ReadScan(metadata.sha256());
  });
}

std::optional<StoredScan> JobStore::GetScan(const std::string& scan_id) {
  return Locked([&] { return ReadScan(scan_id); });
}

std::optional<StoredScan> JobStore::ReadScan(const std::string& scan_id) {
  auto stmt = Query(db_, "SELECT num_points, metadata, range_profile FROM scans WHERE scan_id = ?1",
                    scan_id);
  if (!stmt.executeStep()) return std::nullopt;
  StoredScan scan;
  scan.num_points = static_cast<uint64_t>(stmt.getColumn(0).getInt64());
  scan.metadata = Parse<v1::ScanMetadata>(stmt.getColumn(1).getString(), "scan");
  scan.ranges = RangeProfileFromBytes(stmt.getColumn(2).getString());
  return scan;
}

v1::Job JobStore::CreateJob(v1::Job job, const JobInput& input) {
  return Locked([&] {
    SQLite::Transaction transaction(db_, SQLite::TransactionBehavior::IMMEDIATE);
    const int64_t seq = db_.execAndGet("SELECT COALESCE(MAX(seq), 0) + 1 FROM jobs").getInt64();
    job.set_job_id(JobIdForSeq(seq));
    Run(db_, "INSERT INTO jobs (seq, job_id, state, job, request) VALUES (?1, ?2, ?3, ?4, ?5)", seq,
        job.job_id(), static_cast<int64_t>(job.state()), Blob{Serialize(job)},
        Blob{Serialize(input.request)});
    for (size_t i = 0; i < input.scans.size(); ++i) {
      Run(db_, "INSERT INTO job_scans (job_id, idx, metadata) VALUES (?1, ?2, ?3)", job.job_id(),
          static_cast<int64_t>(i), Blob{Serialize(input.scans[i])});
    }
    transaction.commit();
    return job;
  });
}

std::optional<v1::Job> JobStore::DeleteFinishedJob(const std::string& job_id) {
  return Locked([&] {
    SQLite::Transaction transaction(db_, SQLite::TransactionBehavior::IMMEDIATE);
    std::optional<v1::Job> job = ReadJob(job_id);
    if (!job || !rpc::IsTerminal(job->state())) return job;
    for (const char* table : {"pair_results", "trajectories", "job_scans", "jobs"}) {
      Run(db_, std::string("DELETE FROM ") + table + " WHERE job_id = ?1", job_id);
    }
    transaction.commit();
    return job;
  });
}

std::set<std::string> JobStore::JobIds() {
  return Locked([&] {
    std::set<std::string> ids;
    auto stmt = Query(db_, "SELECT job_id FROM jobs");
    while (stmt.executeStep()) ids.insert(stmt.getColumn(0).getString());
    return ids;
  });
}

std::set<std::string> JobStore::ScansInUse() {
  return Locked([&] {
    std::set<std::string> ids;
    auto stmt = Query(db_, "SELECT metadata FROM job_scans");
    while (stmt.executeStep()) {
      ids.insert(Parse<v1::ScanMetadata>(stmt.getColumn(0).getString(), "scan").sha256());
    }
    return ids;
  });
}

void JobStore::DeleteScan(const std::string& scan_id) {
  Locked([&] { Run(db_, "DELETE FROM scans WHERE scan_id = ?1", scan_id); });
}

std::vector<std::string> JobStore::JobsFinishedBefore(double cutoff) {
  return Locked([&] {
    std::vector<std::string> ids;
    auto stmt = Query(db_, "SELECT job FROM jobs");
    while (stmt.executeStep()) {
      const auto job = ParseJob(stmt.getColumn(0).getString());
      if (rpc::IsTerminal(job.state()) && job.finished_at() < cutoff) ids.push_back(job.job_id());
    }
    return ids;
  });
}

bool JobStore::UpdateJob(const v1::Job& job) {
  return Locked([&] {
    SQLite::Transaction transaction(db_, SQLite::TransactionBehavior::IMMEDIATE);
    const std::optional<v1::Job> stored = ReadJob(job.job_id());
    if (!stored || rpc::IsTerminal(stored->state())) return false;
    v1::Job merged = job;
    if (stored->cancel_requested()) merged.set_cancel_requested(true);
    WriteJob(merged);
    transaction.commit();
    return true;
  });
}

std::optional<v1::Job> JobStore::RequestCancel(const std::string& job_id) {
  return Locked([&] {
    SQLite::Transaction transaction(db_, SQLite::TransactionBehavior::IMMEDIATE);
    std::optional<v1::Job> job = ReadJob(job_id);
    if (!job || rpc::IsTerminal(job->state()) || job->cancel_requested()) return job;
    job->set_cancel_requested(true);
    WriteJob(*job);
    transaction.commit();
    return job;
  });
}

std::optional<v1::Job> JobStore::GetJob(const std::string& job_id) {
  return Locked([&] { return ReadJob(job_id); });
}

std::optional<v1::Job> JobStore::ReadJob(const std::string& job_id) {
  auto stmt = Query(db_, "SELECT job FROM jobs WHERE job_id = ?1", job_id);
  if (!stmt.executeStep()) return std::nullopt;
  return ParseJob(stmt.getColumn(0).getString());
}

void JobStore::WriteJob(const v1::Job& job) {
  Run(db_, "UPDATE jobs SET state = ?2, job = ?3 WHERE job_id = ?1", job.job_id(),
      static_cast<int64_t>(job.state()), Blob{Serialize(job)});
}

std::optional<JobInput> JobStore::GetJobInput(const std::string& job_id) {
  return Locked([&]() -> std::optional<JobInput> {
    auto stmt = Query(db_, "SELECT request FROM jobs WHERE job_id = ?1", job_id);
    if (!stmt.executeStep()) return std::nullopt;
    JobInput input;
    input.request = Parse<v1::SubmitBatchRequest>(stmt.getColumn(0).getString(), "job request");
    auto scans =
        Query(db_, "SELECT metadata FROM job_scans WHERE job_id = ?1 ORDER BY idx", job_id);
    while (scans.executeStep()) {
      input.scans.push_back(Parse<v1::ScanMetadata>(scans.getColumn(0).getString(), "scan"));
    }
    return input;
  });
}

JobPage JobStore::ListJobs(int page_size, const std::string& page_token) {
  if (page_size < 1) throw InputError("page_size: must be at least 1");
  int64_t before = INT64_MAX;
  if (!page_token.empty()) {
    size_t used = 0;
    try {
      before = std::stoll(page_token, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used != page_token.size() || before <= 0) {
      throw InputError("page_token: not a token from a previous ListJobs response");
    }
  }
  return Locked([&] {
    auto stmt = Query(db_, "SELECT seq, job FROM jobs WHERE seq < ?1 ORDER BY seq DESC LIMIT ?2",
                      before, static_cast<int64_t>(page_size) + 1);
    JobPage page;
    int64_t last_seq = 0;
    while (stmt.executeStep()) {
      if (static_cast<int>(page.jobs.size()) == page_size) {
        page.next_page_token = std::to_string(last_seq);
        break;
      }
      last_seq = stmt.getColumn(0).getInt64();
      page.jobs.push_back(ParseJob(stmt.getColumn(1).getString()));
    }
    return page;
  });
}

std::vector<v1::Job> JobStore::UnfinishedJobs() {
  return Locked([&] {
    auto stmt = Query(db_, "SELECT job FROM jobs WHERE state IN (?1, ?2) ORDER BY seq",
                      static_cast<int64_t>(v1::JOB_STATE_QUEUED),
                      static_cast<int64_t>(v1::JOB_STATE_RUNNING));
    std::vector<v1::Job> jobs;
    while (stmt.executeStep()) jobs.push_back(ParseJob(stmt.getColumn(0).getString()));
    return jobs;
  });
}

void JobStore::PutPair(const std::string& job_id, int plan_order, const v1::PairResult& result,
                       const InformationMatrix& information) {
  Locked([&] {
    Run(db_,
        "INSERT OR REPLACE INTO pair_results (job_id, source, target, plan_order, result, "
        "information, answered_by) VALUES (?1, ?2, ?3, ?4, ?5, ?6, ?7)",
        job_id, static_cast<int64_t>(result.source()), static_cast<int64_t>(result.target()),
        static_cast<int64_t>(plan_order), Blob{Serialize(result)},
        Blob{InformationBytes(information)}, rpc::AnsweredBy(result));
  });
}

std::vector<StoredPair> JobStore::GetPairs(const std::string& job_id) {
  return Locked([&] { return ReadPairs(job_id); });
}

std::vector<StoredPair> JobStore::ReadPairs(const std::string& job_id) {
  auto stmt = Query(db_,
                    "SELECT result, information, answered_by FROM pair_results WHERE job_id = ?1 "
                    "ORDER BY plan_order, source, target",
                    job_id);
  std::vector<StoredPair> pairs;
  while (stmt.executeStep()) {
    StoredPair pair;
    pair.result = Parse<v1::PairResult>(stmt.getColumn(0).getString(), "pair");
    pair.information = InformationFromBytes(stmt.getColumn(1).getString());
    // The column speaks for rows stored before the result carried it.
    pair.result.set_answered_by(stmt.getColumn(2).getString());
    pairs.push_back(std::move(pair));
  }
  return pairs;
}

void JobStore::MarkPairsInGraph(const std::string& job_id, const std::vector<PairIndex>& in_graph,
                                const std::map<PairIndex, std::string>& left_out) {
  const std::set<PairIndex> wanted(in_graph.begin(), in_graph.end());
  Locked([&] {
    SQLite::Transaction transaction(db_, SQLite::TransactionBehavior::IMMEDIATE);
    for (StoredPair& pair : ReadPairs(job_id)) {
      const PairIndex index{static_cast<int>(pair.result.source()),
                            static_cast<int>(pair.result.target())};
      pair.result.set_in_graph(wanted.count(index) > 0);
      const auto reason = left_out.find(index);
      pair.result.set_left_out_because(reason != left_out.end() ? reason->second : "");
      Run(db_,
          "UPDATE pair_results SET result = ?4 WHERE job_id = ?1 AND source = ?2 AND target = ?3",
          job_id, static_cast<int64_t>(index.source), static_cast<int64_t>(index.target),
          Blob{Serialize(pair.result)});
    }
    transaction.commit();
  });
}

void JobStore::PutTrajectory(const std::string& job_id,
                             const std::vector<v1::TrajectoryPose>& poses) {
  Locked([&] {
    SQLite::Transaction transaction(db_, SQLite::TransactionBehavior::IMMEDIATE);
    Run(db_, "DELETE FROM trajectories WHERE job_id = ?1", job_id);
    for (const v1::TrajectoryPose& pose : poses) {
      Run(db_, "INSERT INTO trajectories (job_id, idx, pose) VALUES (?1, ?2, ?3)", job_id,
          static_cast<int64_t>(pose.index()), Blob{Serialize(pose)});
    }
    transaction.commit();
  });
}

namespace {

// Where a results page resumes: after the pair (plan_order, source, target),
// at the pose `pose`. The token is the four numbers, colon-separated.
struct ResultsCursor {
  int64_t plan_order = -1, source = -1, target = -1, pose = 0;
};

ResultsCursor ParseResultsToken(const std::string& token) {
  ResultsCursor cursor;
  if (token.empty()) return cursor;
  long long v[4];
  int used = 0;
  if (std::sscanf(token.c_str(), "%lld:%lld:%lld:%lld%n", &v[0], &v[1], &v[2], &v[3], &used) != 4 ||
      static_cast<size_t>(used) != token.size() || v[3] < 0) {
    throw InputError("page_token: not a token from a previous GetResults response");
  }
  return {v[0], v[1], v[2], v[3]};
}

}  // namespace

ResultsPage JobStore::GetResultsPage(const std::string& job_id, int page_size,
                                     const std::string& page_token) {
  ResultsCursor cursor = ParseResultsToken(page_token);
  return Locked([&] {
    ResultsPage page;
    bool more = false;
    // One row past the page says whether another page follows.
    auto pairs = Query(db_,
                       "SELECT plan_order, source, target, result, answered_by FROM pair_results "
                       "WHERE job_id = ?1 AND (plan_order, source, target) > (?2, ?3, ?4) "
                       "ORDER BY plan_order, source, target LIMIT ?5",
                       job_id, cursor.plan_order, cursor.source, cursor.target,
                       static_cast<int64_t>(page_size) + 1);
    while (pairs.executeStep()) {
      if (static_cast<int>(page.pairs.size()) == page_size) {
        more = true;
        break;
      }
      v1::PairResult result = Parse<v1::PairResult>(pairs.getColumn(3).getString(), "pair");
      result.set_answered_by(pairs.getColumn(4).getString());  // as in GetPairs
      page.pairs.push_back(std::move(result));
      cursor.plan_order = pairs.getColumn(0).getInt64();
      cursor.source = pairs.getColumn(1).getInt64();
      cursor.target = pairs.getColumn(2).getInt64();
    }
    auto poses = Query(
        db_,
        "SELECT idx, pose FROM trajectories WHERE job_id = ?1 AND idx >= ?2 ORDER BY idx LIMIT ?3",
        job_id, cursor.pose, static_cast<int64_t>(page_size) + 1);
    int64_t next_pose = cursor.pose;
    while (poses.executeStep()) {
      if (static_cast<int>(page.poses.size()) == page_size) {
        more = true;
        break;
      }
      page.poses.push_back(Parse<v1::TrajectoryPose>(poses.getColumn(1).getString(), "pose"));
      next_pose = poses.getColumn(0).getInt64() + 1;
    }
    if (more) {
      page.next_page_token = std::to_string(cursor.plan_order) + ":" +
                             std::to_string(cursor.source) + ":" + std::to_string(cursor.target) +
                             ":" + std::to_string(next_pose);
    }
    return page;
  });
}

void JobStore::Checkpoint() {
  Locked([&] { db_.exec("PRAGMA wal_checkpoint(TRUNCATE)"); });
}

}  // namespace boicp::server
