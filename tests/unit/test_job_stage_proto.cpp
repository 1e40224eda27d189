// The job's stage in the API: every map stage has its code, and the code and
// the name a job carries side by side always agree.

#include <gtest/gtest.h>

#include "boicp/mapping/map_stage.hpp"
#include "boicp/rpc/proto_convert.hpp"

namespace boicp::rpc {
namespace {

TEST(JobStageProto, EveryMapStageHasACodeNamedAsTheStage) {
  for (const MapStage stage : {MapStage::kRegistering, MapStage::kChaining, MapStage::kOptimising,
                               MapStage::kFusing, MapStage::kWriting}) {
    v1::Job job;
    SetJobStage(job, JobStageOf(stage));
    EXPECT_NE(job.stage_code(), v1::JOB_STAGE_UNSPECIFIED) << MapStageName(stage);
    EXPECT_EQ(job.stage(), MapStageName(stage));
  }
}

TEST(JobStageProto, EveryCodeRoundTripsThroughItsName) {
  for (int value = v1::JobStage_MIN; value <= v1::JobStage_MAX; ++value) {
    if (!v1::JobStage_IsValid(value)) continue;
    v1::Job job;
    SetJobStage(job, static_cast<v1::JobStage>(value));
    EXPECT_EQ(JobStageFromName(job.stage()), job.stage_code()) << job.stage();
  }
  v1::Job done;
  SetJobStage(done, v1::JOB_STAGE_DONE);
  EXPECT_EQ(done.stage(), "done");
  EXPECT_EQ(JobStageFromName("resting"), v1::JOB_STAGE_UNSPECIFIED);
}

}  // namespace
}  // namespace boicp::rpc
