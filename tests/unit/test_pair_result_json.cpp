// A pair result as JSON, generated from its field list: each format carries
// its own fields, round trips them exactly, and names what it cannot read.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "boicp/settings/pair_result_json.hpp"
#include "pair_result_example.hpp"

namespace boicp::settings {
namespace {

using nlohmann::json;
using ::testing::HasSubstr;

TEST(PairResultJson, EachFormatRoundTripsItsFieldsExactly) {
  const PairResult r = ExamplePairResult();
  for (const PairResultFormat format : {kPairFile, kPairListing, kPairApi}) {
    const json written = PairResultToJson(r, format);
    EXPECT_EQ(PairResultToJson(PairResultFromJson(json::parse(written.dump()), format), format),
              written)
        << format;
  }
  const PairResult read = PairResultFromJson(PairResultToJson(r, kPairFile), kPairFile);
  EXPECT_TRUE(read.transform.isApprox(r.transform, 0.0));
  EXPECT_EQ(read.information, r.information);
  EXPECT_EQ(read.seed, r.seed);
  EXPECT_EQ(read.answered_by, Rung::kShortSearch);
  ASSERT_TRUE(read.unconstrained.has_value());
  ASSERT_EQ(read.unconstrained->size(), 2u);
  EXPECT_EQ((*read.unconstrained)[1].extent, 0.75);
}

TEST(PairResultJson, FreeSlidesNameTheirAxisExtentAndShare) {
  const json listing = PairResultToJson(ExamplePairResult(), kPairListing);
  const json& slide = listing["unconstrained"][0];
  EXPECT_EQ(slide["axis"], json({0.6, 0.8, 0.0}));
  EXPECT_EQ(slide["extent_m"], 2.5);
  EXPECT_EQ(slide["across_share"], 0.004);
  json bad = slide;
  bad["axis"] = json({1.0, 0.0});
  EXPECT_THROW(FreeSlideFromJson(bad), InputError);
}

TEST(PairResultJson, EachFormatCarriesItsOwnFields) {
  const PairResult r = ExamplePairResult();
  const json file = PairResultToJson(r, kPairFile);
  const json listing = PairResultToJson(r, kPairListing);
  const json api = PairResultToJson(r, kPairApi);
  for (const json* j : {&file, &listing, &api}) {
    EXPECT_EQ((*j)["source"], 3);
    EXPECT_EQ((*j)["target"], 7);
    EXPECT_EQ((*j)["answered_by"], "short-search");
    EXPECT_EQ((*j)["transform"].size(), 4u);
  }
  EXPECT_EQ(file["information"].size(), 6u);
  EXPECT_FALSE(listing.contains("information"));
  EXPECT_FALSE(file.contains("in_graph"));
  EXPECT_EQ(listing["in_graph"], false);
  EXPECT_FALSE(listing.contains("finished_at"));
  EXPECT_EQ(api["finished_at"], 1764931200.25);
}

TEST(PairResultJson, UnknownValuesAreNullBothWays) {
  PairResult r = ExamplePairResult();
  r.overlap.reset();
  r.search_reach.reset();
  r.unconstrained.reset();
  const json j = PairResultToJson(r, kPairListing);
  EXPECT_TRUE(j["unconstrained"].is_null());
  EXPECT_TRUE(j["overlap"].is_null());
  EXPECT_TRUE(j["search_reach"].is_null());
  const PairResult read = PairResultFromJson(j, kPairListing);
  EXPECT_FALSE(read.overlap.has_value());
  EXPECT_FALSE(read.search_reach.has_value());
  EXPECT_FALSE(read.unconstrained.has_value());
}

TEST(PairResultJson, AMissingOrMalformedKeyIsNamed) {
  const json good = PairResultToJson(ExamplePairResult(), kPairFile);
  const auto error_of = [](const json& j) {
    try {
      PairResultFromJson(j, kPairFile);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  json missing = good;
  missing.erase("fitness");
  EXPECT_THAT(error_of(missing), HasSubstr("fitness"));
  json rung = good;
  rung["answered_by"] = "guesswork";
  EXPECT_THAT(error_of(rung), HasSubstr("answered_by: unknown rung 'guesswork'"));
  json rows = good;
  rows["information"].erase(5);
  EXPECT_THAT(error_of(rows), HasSubstr("information: expected 6 rows"));
  json type = good;
  type["evaluations"] = "many";
  EXPECT_THAT(error_of(type), HasSubstr("evaluations"));
}

}  // namespace
}  // namespace boicp::settings
