// The rung words a result is stored under read back, and the count per rung
// that `boicp map`, `merge` and `show` close with.

#include <gtest/gtest.h>

#include "boicp/settings/rung_summary.hpp"

namespace boicp::settings {
namespace {

TEST(RungSummary, EveryRungReadsBackFromItsName) {
  for (const Rung rung :
       {Rung::kPrior, Rung::kFeatures, Rung::kShortSearch, Rung::kFullSearch, Rung::kRetry}) {
    EXPECT_EQ(RungFromName(RungName(rung)), rung) << RungName(rung);
  }
  EXPECT_FALSE(RungFromName(""));
  EXPECT_FALSE(RungFromName("search"));  // an attempt's kind, not a rung
  EXPECT_FALSE(RungFromName("Prior"));
}

TEST(RungSummary, CountsEachRungInLadderOrder) {
  std::vector<Rung> answers;
  // Out of order, as pairs finish.
  answers.push_back(Rung::kRetry);
  answers.insert(answers.end(), 2, Rung::kShortSearch);
  answers.insert(answers.end(), 31, Rung::kPrior);
  answers.push_back(Rung::kFullSearch);
  answers.insert(answers.end(), 5, Rung::kFeatures);
  EXPECT_EQ(RungSummary(answers), "31 prior, 5 features, 2 short, 1 full, 1 retry");
}

TEST(RungSummary, RungsThatAnsweredNothingAreLeftOut) {
  EXPECT_EQ(RungSummary({Rung::kRetry, Rung::kFeatures, Rung::kFeatures}), "2 features, 1 retry");
  EXPECT_EQ(RungSummary({Rung::kFullSearch}), "1 full");
  EXPECT_EQ(RungSummary({}), "");
}

}  // namespace
}  // namespace boicp::settings
