// A database written before the job store's later columns existed (a job's
// unended runs, the rung that answered a pair) still opens, is brought to
// the current schema version, and its rows read the columns' defaults; a
// job stored before Job.stage_code gets it from its stage's name; a
// database of a newer version is refused.

#include <unistd.h>

#include <filesystem>

#include <gtest/gtest.h>

#include "job_store.hpp"
#include "sqlite_db.hpp"

namespace boicp::server {
namespace {

namespace fs = std::filesystem;

// The two tables as the first release created them.
constexpr const char* kFirstReleaseTables = R"sql(
CREATE TABLE jobs (
  seq INTEGER PRIMARY KEY,
  job_id TEXT NOT NULL UNIQUE,
  state INTEGER NOT NULL,
  job BLOB NOT NULL,
  request BLOB NOT NULL
);
CREATE TABLE pair_results (
  job_id TEXT NOT NULL,
  source INTEGER NOT NULL,
  target INTEGER NOT NULL,
  plan_order INTEGER NOT NULL,
  result BLOB NOT NULL,
  information BLOB NOT NULL,
  PRIMARY KEY (job_id, source, target)
);
)sql";

constexpr const char* kJobId = "job-000001";

v1::PairResult Result(uint32_t source, double fitness) {
  v1::PairResult result;
  result.set_source(source);
  result.set_target(source + 1);
  result.set_fitness(fitness);
  return result;
}

// A first-release database holding one running job and one finished pair,
// whose result predates answered_by.
void WriteFirstReleaseDatabase(const std::string& path) {
  SQLite::Database db = OpenDatabase(path);
  db.exec(kFirstReleaseTables);
  v1::Job job;
  job.set_job_id(kJobId);
  job.set_state(v1::JOB_STATE_RUNNING);
  job.set_stage("fusing");  // the name alone, as before stage_code
  Run(db, "INSERT INTO jobs (seq, job_id, state, job, request) VALUES (1, ?1, ?2, ?3, '')",
      std::string(kJobId), static_cast<int64_t>(job.state()), Blob{job.SerializeAsString()});
  Run(db,
      "INSERT INTO pair_results (job_id, source, target, plan_order, result, information) "
      "VALUES (?1, 0, 1, 0, ?2, '')",
      std::string(kJobId), Blob{Result(0, 0.75).SerializeAsString()});
}

int64_t UserVersion(const std::string& path) {
  SQLite::Database db = OpenDatabase(path);
  return db.execAndGet("PRAGMA user_version").getInt64();
}

class JobStoreMigration : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("boicp_store_migration_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    path_ = (dir_ / "boicpd.sqlite").string();
  }
  void TearDown() override { fs::remove_all(dir_); }

  fs::path dir_;
  std::string path_;
};

TEST_F(JobStoreMigration, AFirstReleaseDatabaseOpensWithTheColumnsDefaults) {
  WriteFirstReleaseDatabase(path_);
  {
    JobStore store(path_);
    const std::vector<StoredPair> pairs = store.GetPairs(kJobId);
    ASSERT_EQ(pairs.size(), 1u);
    EXPECT_EQ(pairs[0].result.fitness(), 0.75);
    // Every answer before the ladder came from the full search.
    EXPECT_EQ(pairs[0].result.answered_by(), "full-search");
    EXPECT_EQ(store.UnendedRuns(kJobId), 0);
    EXPECT_EQ(store.BeginRun(kJobId), 1);
    const std::optional<v1::Job> job = store.GetJob(kJobId);
    ASSERT_TRUE(job.has_value());
    EXPECT_EQ(job->stage_code(), v1::JOB_STAGE_FUSING);
    EXPECT_EQ(job->stage(), "fusing");

    v1::PairResult next = Result(1, 0.5);
    next.set_answered_by("prior");
    store.PutPair(kJobId, 1, next, InformationMatrix::Identity());
  }
  // Opened again: the columns are there now, and each row keeps its rung.
  EXPECT_EQ(UserVersion(path_), kSchemaVersion);
  JobStore store(path_);
  const std::vector<StoredPair> pairs = store.GetPairs(kJobId);
  ASSERT_EQ(pairs.size(), 2u);
  EXPECT_EQ(pairs[0].result.answered_by(), "full-search");
  EXPECT_EQ(pairs[1].result.answered_by(), "prior");
  EXPECT_EQ(store.UnendedRuns(kJobId), 1);
}

TEST_F(JobStoreMigration, AResultWithoutARungIsStoredAsTheFullSearch) {
  JobStore store(path_);
  v1::Job job;
  job.set_state(v1::JOB_STATE_QUEUED);
  job = store.CreateJob(job, JobInput{});
  store.PutPair(job.job_id(), 0, Result(0, 0.9), InformationMatrix::Identity());
  v1::PairResult retried = Result(1, 0.8);
  retried.set_answered_by("retry");
  store.PutPair(job.job_id(), 1, retried, InformationMatrix::Identity());
  store.MarkPairsInGraph(job.job_id(), {{0, 1}});
  const std::vector<StoredPair> pairs = store.GetPairs(job.job_id());
  ASSERT_EQ(pairs.size(), 2u);
  EXPECT_EQ(pairs[0].result.answered_by(), "full-search");
  EXPECT_EQ(pairs[1].result.answered_by(), "retry");
  EXPECT_FALSE(pairs[1].result.in_graph());
}

// A database written by a later boicpd (a higher schema version) is refused
// with both versions named, and left as it was.
TEST_F(JobStoreMigration, ADatabaseOfANewerSchemaIsRefusedAndLeftAsItWas) {
  { JobStore created(path_); }
  {
    SQLite::Database db = OpenDatabase(path_);
    db.exec("PRAGMA user_version = " + std::to_string(kSchemaVersion + 1));
  }
  try {
    JobStore store(path_);
    FAIL() << "a newer database was opened";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("schema version " + std::to_string(kSchemaVersion + 1) +
                                         " is newer than this boicpd reads (" +
                                         std::to_string(kSchemaVersion) + ")"),
              std::string::npos)
        << e.what();
  }
  EXPECT_EQ(UserVersion(path_), kSchemaVersion + 1);
}

}  // namespace
}  // namespace boicp::server
