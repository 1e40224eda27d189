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

JobStore::JobStore(const std::string& path) : db_(path) {
  // WAL lets readers run beside the writer; FULL syncs every commit, so an
  // acknowledged upload or finished pair survives even a power cut.
  db_.Exec("PRAGMA journal_mode=WAL");
  db_.Exec("PRAGMA synchronous=FULL");
  db_.Exec("PRAGMA foreign_keys=ON");
  db_.Exec(kSchema);
  Migrate();
}

void JobStore::Migrate() {
  auto read = db_.Prepare("PRAGMA user_version");
  const int64_t version = read.Step() ? read.ColumnInt(0) : 0;
  if (version > kSchemaVersion) {
    throw std::runtime_error("data store: its schema version " + std::to_string(version) +
                             " is newer than this boicpd reads (" + std::to_string(kSchemaVersion) +
                             "); run the boicpd that wrote it, or use another --data-dir");
  }
  if (version == kSchemaVersion) return;
  SqliteDatabase::Transaction transaction(db_);
  // Version 0: databases from before the version was recorded, which may
  // lack the columns added since the first release. Older rows read their
  // defaults: no unended runs, answered by the full search, as every pair
  // was before the escalation ladder, and no range profile.
  AddMissingColumn("jobs", "unended_runs", "INTEGER NOT NULL DEFAULT 0");
  AddMissingColumn("pair_results", "answered_by", "TEXT NOT NULL DEFAULT 'full-search'");
  AddMissingColumn("scans", "range_profile", "BLOB NOT NULL DEFAULT x''");
  db_.Exec("PRAGMA user_version = " + std::to_string(kSchemaVersion));
  transaction.Commit();
}

void JobStore::AddMissingColumn(const std::string& table, const std::string& column,
                                const std::string& definition) {
  auto columns = db_.Prepare("SELECT name FROM pragma_table_info(?1)");
  columns.Bind(1, table);
  while (columns.Step()) {
    if (columns.ColumnText(0) == column) return;
  }
  db_.Exec("ALTER TABLE " + table + " ADD COLUMN " + column + " " + definition);
}

int JobStore::BeginRun(const std::string& job_id) {
  std::lock_guard<std::mutex> lock(mutex_);
  db_.Prepare("UPDATE jobs SET unended_runs = unended_runs + 1 WHERE job_id = ?1")
      .Bind(1, job_id)
      .Run();
  return ReadUnendedRuns(job_id);
}

void JobStore::EndRun(const std::string& job_id) {
  std::lock_guard<std::mutex> lock(mutex_);
  db_.Prepare("UPDATE jobs SET unended_runs = 0 WHERE job_id = ?1").Bind(1, job_id).Run();
}

int JobStore::UnendedRuns(const std::string& job_id) {
  std::lock_guard<std::mutex> lock(mutex_);
  return ReadUnendedRuns(job_id);
}

int JobStore::ReadUnendedRuns(const std::string& job_id) {
  auto stmt = db_.Prepare("SELECT unended_runs FROM jobs WHERE job_id = ?1");
  stmt.Bind(1, job_id);
  return stmt.Step() ? static_cast<int>(stmt.ColumnInt(0)) : 0;
}

StoredScan JobStore::PutScan(const v1::ScanMetadata& metadata, uint64_t num_points,
                             const RangeProfile& ranges) {
  std::lock_guard<std::mutex> lock(mutex_);
  // An existing record is kept: of two first uploads racing, the second
  // finds the first's record and is answered with it.
  db_.Prepare(
         "INSERT INTO scans (scan_id, num_points, metadata, range_profile) "
         "VALUES (?1, ?2, ?3, ?4) "
         "ON CONFLICT (scan_id) DO UPDATE SET range_profile = ?4 "
         "WHERE length(scans.range_profile) = 0 AND scans.metadata = ?3")
      .Bind(1, metadata.sha256())
      .Bind(2, static_cast<int64_t>(num_points))
      .BindBlob(3, Serialize(metadata))
      .BindBlob(4, RangeProfileBytes(ranges))
      .Run();
  return *ReadScan(metadata.sha256());
}

std::optional<StoredScan> JobStore::GetScan(const std::string& scan_id) {
  std::lock_guard<std::mutex> lock(mutex_);
  return ReadScan(scan_id);
}

std::optional<StoredScan> JobStore::ReadScan(const std::string& scan_id) {
  auto stmt =
      db_.Prepare("SELECT num_points, metadata, range_profile FROM scans WHERE scan_id = ?1");
  stmt.Bind(1, scan_id);
  if (!stmt.Step()) return std::nullopt;
  StoredScan scan;
  scan.num_points = static_cast<uint64_t>(stmt.ColumnInt(0));
  scan.metadata = Parse<v1::ScanMetadata>(stmt.ColumnBlob(1), "scan");
  scan.ranges = RangeProfileFromBytes(stmt.ColumnBlob(2));
  return scan;
}

v1::Job JobStore::CreateJob(v1::Job job, const JobInput& input) {
  std::lock_guard<std::mutex> lock(mutex_);
  SqliteDatabase::Transaction transaction(db_);
  auto next = db_.Prepare("SELECT COALESCE(MAX(seq), 0) + 1 FROM jobs");
  next.Step();
  const int64_t seq = next.ColumnInt(0);
  job.set_job_id(JobIdForSeq(seq));
  db_.Prepare("INSERT INTO jobs (seq, job_id, state, job, request) VALUES (?1, ?2, ?3, ?4, ?5)")
      .Bind(1, seq)
      .Bind(2, job.job_id())
      .Bind(3, static_cast<int64_t>(job.state()))
      .BindBlob(4, Serialize(job))
      .BindBlob(5, Serialize(input.request))
      .Run();
  auto insert_scan =
      db_.Prepare("INSERT INTO job_scans (job_id, idx, metadata) VALUES (?1, ?2, ?3)");
  for (size_t i = 0; i < input.scans.size(); ++i) {
    insert_scan.Bind(1, job.job_id())
        .Bind(2, static_cast<int64_t>(i))
        .BindBlob(3, Serialize(input.scans[i]))
        .Run();
    insert_scan.Reset();
  }
  transaction.Commit();
  return job;
}

std::optional<v1::Job> JobStore::DeleteFinishedJob(const std::string& job_id) {
  std::lock_guard<std::mutex> lock(mutex_);
  SqliteDatabase::Transaction transaction(db_);
  std::optional<v1::Job> job = ReadJob(job_id);
  if (!job || !rpc::IsTerminal(job->state())) return job;
  for (const char* table : {"pair_results", "trajectories", "job_scans", "jobs"}) {
    db_.Prepare(std::string("DELETE FROM ") + table + " WHERE job_id = ?1").Bind(1, job_id).Run();
  }
  transaction.Commit();
  return job;
}

std::set<std::string> JobStore::JobIds() {
  std::lock_guard<std::mutex> lock(mutex_);
  std::set<std::string> ids;
  auto stmt = db_.Prepare("SELECT job_id FROM jobs");
  while (stmt.Step()) ids.insert(stmt.ColumnText(0));
  return ids;
}

std::set<std::string> JobStore::ScansInUse() {
  std::lock_guard<std::mutex> lock(mutex_);
  std::set<std::string> ids;
  auto stmt = db_.Prepare("SELECT metadata FROM job_scans");
  while (stmt.Step()) ids.insert(Parse<v1::ScanMetadata>(stmt.ColumnBlob(0), "scan").sha256());
  return ids;
}

void JobStore::DeleteScan(const std::string& scan_id) {
  std::lock_guard<std::mutex> lock(mutex_);
  db_.Prepare("DELETE FROM scans WHERE scan_id = ?1").Bind(1, scan_id).Run();
}

std::vector<std::string> JobStore::JobsFinishedBefore(double cutoff) {
  std::lock_guard<std::mutex> lock(mutex_);
  std::vector<std::string> ids;
  auto stmt = db_.Prepare("SELECT job FROM jobs");
  while (stmt.Step()) {
    const auto job = ParseJob(stmt.ColumnBlob(0));
    if (rpc::IsTerminal(job.state()) && job.finished_at() < cutoff) ids.push_back(job.job_id());
  }
  return ids;
}

bool JobStore::UpdateJob(const v1::Job& job) {
  std::lock_guard<std::mutex> lock(mutex_);
  SqliteDatabase::Transaction transaction(db_);
  const std::optional<v1::Job> stored = ReadJob(job.job_id());
  if (!stored || rpc::IsTerminal(stored->state())) return false;
  v1::Job merged = job;
  if (stored->cancel_requested()) merged.set_cancel_requested(true);
  WriteJob(merged);
  transaction.Commit();
  return true;
}

std::optional<v1::Job> JobStore::RequestCancel(const std::string& job_id) {
  std::lock_guard<std::mutex> lock(mutex_);
  SqliteDatabase::Transaction transaction(db_);
  std::optional<v1::Job> job = ReadJob(job_id);
  if (!job || rpc::IsTerminal(job->state()) || job->cancel_requested()) return job;
  job->set_cancel_requested(true);
  WriteJob(*job);
  transaction.Commit();
  return job;
}

std::optional<v1::Job> JobStore::GetJob(const std::string& job_id) {
  std::lock_guard<std::mutex> lock(mutex_);
  return ReadJob(job_id);
}

std::optional<v1::Job> JobStore::ReadJob(const std::string& job_id) {
  auto stmt = db_.Prepare("SELECT job FROM jobs WHERE job_id = ?1");
  stmt.Bind(1, job_id);
  if (!stmt.Step()) return std::nullopt;
  return ParseJob(stmt.ColumnBlob(0));
}

void JobStore::WriteJob(const v1::Job& job) {
  db_.Prepare("UPDATE jobs SET state = ?2, job = ?3 WHERE job_id = ?1")
      .Bind(1, job.job_id())
      .Bind(2, static_cast<int64_t>(job.state()))
      .BindBlob(3, Serialize(job))
      .Run();
}

std::optional<JobInput> JobStore::GetJobInput(const std::string& job_id) {
  std::lock_guard<std::mutex> lock(mutex_);
  auto stmt = db_.Prepare("SELECT request FROM jobs WHERE job_id = ?1");
  stmt.Bind(1, job_id);
  if (!stmt.Step()) return std::nullopt;
  JobInput input;
  input.request = Parse<v1::SubmitBatchRequest>(stmt.ColumnBlob(0), "job request");
  auto scans = db_.Prepare("SELECT metadata FROM job_scans WHERE job_id = ?1 ORDER BY idx");
  scans.Bind(1, job_id);
  while (scans.Step()) input.scans.push_back(Parse<v1::ScanMetadata>(scans.ColumnBlob(0), "scan"));
  return input;
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
  std::lock_guard<std::mutex> lock(mutex_);
  auto stmt = db_.Prepare("SELECT seq, job FROM jobs WHERE seq < ?1 ORDER BY seq DESC LIMIT ?2");
  stmt.Bind(1, before).Bind(2, static_cast<int64_t>(page_size) + 1);
  JobPage page;
  int64_t last_seq = 0;
  while (stmt.Step()) {
    if (static_cast<int>(page.jobs.size()) == page_size) {
      page.next_page_token = std::to_string(last_seq);
      break;
    }
    last_seq = stmt.ColumnInt(0);
    page.jobs.push_back(ParseJob(stmt.ColumnBlob(1)));
  }
  return page;
}

std::vector<v1::Job> JobStore::UnfinishedJobs() {
  std::lock_guard<std::mutex> lock(mutex_);
  auto stmt = db_.Prepare("SELECT job FROM jobs WHERE state IN (?1, ?2) ORDER BY seq");
  stmt.Bind(1, static_cast<int64_t>(v1::JOB_STATE_QUEUED))
      .Bind(2, static_cast<int64_t>(v1::JOB_STATE_RUNNING));
  std::vector<v1::Job> jobs;
  while (stmt.Step()) jobs.push_back(ParseJob(stmt.ColumnBlob(0)));
  return jobs;
}

void JobStore::PutPair(const std::string& job_id, int plan_order, const v1::PairResult& result,
                       const InformationMatrix& information) {
  std::lock_guard<std::mutex> lock(mutex_);
  db_.Prepare(
         "INSERT OR REPLACE INTO pair_results (job_id, source, target, plan_order, result, "
         "information, answered_by) VALUES (?1, ?2, ?3, ?4, ?5, ?6, ?7)")
      .Bind(1, job_id)
      .Bind(2, static_cast<int64_t>(result.source()))
      .Bind(3, static_cast<int64_t>(result.target()))
      .Bind(4, static_cast<int64_t>(plan_order))
      .BindBlob(5, Serialize(result))
      .BindBlob(6, InformationBytes(information))
      .Bind(7, rpc::AnsweredBy(result))
      .Run();
}

std::vector<StoredPair> JobStore::GetPairs(const std::string& job_id) {
  std::lock_guard<std::mutex> lock(mutex_);
  auto stmt = db_.Prepare(
      "SELECT result, information, answered_by FROM pair_results WHERE job_id = ?1 "
      "ORDER BY plan_order, source, target");
  stmt.Bind(1, job_id);
  std::vector<StoredPair> pairs;
  while (stmt.Step()) {
    StoredPair pair;
    pair.result = Parse<v1::PairResult>(stmt.ColumnBlob(0), "pair");
    pair.information = InformationFromBytes(stmt.ColumnBlob(1));
    // The column speaks for rows stored before the result carried it.
    pair.result.set_answered_by(stmt.ColumnText(2));
    pairs.push_back(std::move(pair));
  }
  return pairs;
}

void JobStore::MarkPairsInGraph(const std::string& job_id, const std::vector<PairIndex>& in_graph) {
  const std::set<PairIndex> wanted(in_graph.begin(), in_graph.end());
  std::vector<StoredPair> pairs = GetPairs(job_id);
  std::lock_guard<std::mutex> lock(mutex_);
  SqliteDatabase::Transaction transaction(db_);
  for (StoredPair& pair : pairs) {
    const PairIndex index{static_cast<int>(pair.result.source()),
                          static_cast<int>(pair.result.target())};
    pair.result.set_in_graph(wanted.count(index) > 0);
    db_.Prepare(
           "UPDATE pair_results SET result = ?4 WHERE job_id = ?1 AND source = ?2 AND target = ?3")
        .Bind(1, job_id)
        .Bind(2, static_cast<int64_t>(index.source))
        .Bind(3, static_cast<int64_t>(index.target))
        .BindBlob(4, Serialize(pair.result))
        .Run();
  }
  transaction.Commit();
}

void JobStore::PutTrajectory(const std::string& job_id,
                             const std::vector<v1::TrajectoryPose>& poses) {
  std::lock_guard<std::mutex> lock(mutex_);
  SqliteDatabase::Transaction transaction(db_);
  db_.Prepare("DELETE FROM trajectories WHERE job_id = ?1").Bind(1, job_id).Run();
  for (const v1::TrajectoryPose& pose : poses) {
    db_.Prepare("INSERT INTO trajectories (job_id, idx, pose) VALUES (?1, ?2, ?3)")
        .Bind(1, job_id)
        .Bind(2, static_cast<int64_t>(pose.index()))
        .BindBlob(3, Serialize(pose))
        .Run();
  }
  transaction.Commit();
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
  std::lock_guard<std::mutex> lock(mutex_);
  ResultsPage page;
  bool more = false;
  // One row past the page says whether another page follows.
  auto pairs = db_.Prepare(
      "SELECT plan_order, source, target, result, answered_by FROM pair_results "
      "WHERE job_id = ?1 AND (plan_order, source, target) > (?2, ?3, ?4) "
      "ORDER BY plan_order, source, target LIMIT ?5");
  pairs.Bind(1, job_id)
      .Bind(2, cursor.plan_order)
      .Bind(3, cursor.source)
      .Bind(4, cursor.target)
      .Bind(5, static_cast<int64_t>(page_size) + 1);
  while (pairs.Step()) {
    if (static_cast<int>(page.pairs.size()) == page_size) {
      more = true;
      break;
    }
    v1::PairResult result = Parse<v1::PairResult>(pairs.ColumnBlob(3), "pair");
    result.set_answered_by(pairs.ColumnText(4));  // as in GetPairs
    page.pairs.push_back(std::move(result));
    cursor.plan_order = pairs.ColumnInt(0);
    cursor.source = pairs.ColumnInt(1);
    cursor.target = pairs.ColumnInt(2);
  }
  auto poses = db_.Prepare(
      "SELECT idx, pose FROM trajectories WHERE job_id = ?1 AND idx >= ?2 ORDER BY idx LIMIT ?3");
  poses.Bind(1, job_id).Bind(2, cursor.pose).Bind(3, static_cast<int64_t>(page_size) + 1);
  int64_t next_pose = cursor.pose;
  while (poses.Step()) {
    if (static_cast<int>(page.poses.size()) == page_size) {
      more = true;
      break;
    }
    page.poses.push_back(Parse<v1::TrajectoryPose>(poses.ColumnBlob(1), "pose"));
    next_pose = poses.ColumnInt(0) + 1;
  }
  if (more) {
    page.next_page_token = std::to_string(cursor.plan_order) + ":" + std::to_string(cursor.source) +
                           ":" + std::to_string(cursor.target) + ":" + std::to_string(next_pose);
  }
  return page;
}

void JobStore::Checkpoint() {
  std::lock_guard<std::mutex> lock(mutex_);
  db_.Exec("PRAGMA wal_checkpoint(TRUNCATE)");
}

}  // namespace boicp::server
