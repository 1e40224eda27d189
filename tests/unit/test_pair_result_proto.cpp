// A pair result as boicp.v1.PairResult, generated from its field list: the
// field list and the message agree, every API field survives the message,
// and messages stored before a field existed read as the result documents.

#include <set>

#include <gtest/gtest.h>

#include "boicp/rpc/pair_result_proto.hpp"
#include "boicp/settings/pair_result_json.hpp"
#include "pair_result_example.hpp"

namespace boicp::rpc {
namespace {

TEST(PairResultProto, EveryMessageFieldIsTheKeyAScanIdOrAnApiField) {
  std::set<std::string> api_fields;
  for (const PairResultField& field : PairResultFields()) {
    if (field.formats & kPairApi) api_fields.insert(field.name);
  }
  std::set<std::string> message_fields;
  const auto* descriptor = v1::PairResult::descriptor();
  for (int i = 0; i < descriptor->field_count(); ++i) {
    const std::string name = descriptor->field(i)->name();
    if (name != "source" && name != "target" && name != "source_scan_id" &&
        name != "target_scan_id") {
      message_fields.insert(name);
    }
  }
  EXPECT_EQ(api_fields, message_fields);
}

TEST(PairResultProto, EveryApiFieldSurvivesTheMessage) {
  const PairResult r = ExamplePairResult();
  v1::PairResult message;
  PairResultToProto(r, &message);
  v1::PairResult parsed;
  ASSERT_TRUE(parsed.ParseFromString(message.SerializeAsString()));
  const PairResult read = PairResultFromProto(parsed);
  EXPECT_EQ(settings::PairResultToJson(read, kPairApi), settings::PairResultToJson(r, kPairApi));
  // The daemon keeps the information matrix beside the message.
  EXPECT_EQ(read.information, InformationMatrix::Identity());
}

TEST(PairResultProto, AMessageStoredBeforeTheLadderAndCalibrationReadsTrustedAndFull) {
  PairResult r = ExamplePairResult();
  r.overlap.reset();
  r.search_reach.reset();
  v1::PairResult message;
  PairResultToProto(r, &message);
  message.clear_doubtful();
  message.clear_answered_by();
  const PairResult read = PairResultFromProto(message);
  EXPECT_EQ(read.confidence, 1.0);
  EXPECT_FALSE(read.doubtful);
  EXPECT_EQ(read.answered_by, Rung::kFullSearch);
  EXPECT_FALSE(read.overlap.has_value());
  EXPECT_FALSE(read.search_reach.has_value());
}

TEST(PairResultProto, AnUnknownRungOrABrokenTransformIsAnInputError) {
  v1::PairResult message;
  PairResultToProto(ExamplePairResult(), &message);
  v1::PairResult rung = message;
  rung.set_answered_by("guesswork");
  EXPECT_THROW(PairResultFromProto(rung), InputError);
  v1::PairResult transform = message;
  transform.mutable_transform()->set_m(0, 2.0);
  EXPECT_THROW(PairResultFromProto(transform), InputError);
}

}  // namespace
}  // namespace boicp::rpc
