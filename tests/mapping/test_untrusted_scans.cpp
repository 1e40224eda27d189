// Scans no trusted pair ties to the others (mapping/untrusted_scans).

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "boicp/mapping/untrusted_scans.hpp"
#include "boicp/registration/bo_icp.hpp"

namespace boicp {
namespace {

PairConstraint Pair(int source, int target, double confidence) {
  PairConstraint c;
  c.pair = {source, target};
  c.confidence = confidence;
  return c;
}

TEST(ScansWithoutTrustedPair, NamesScansTouchedOnlyByDoubtfulOrUnusedPairs) {
  // 0-1 trusted, 1-2 and 2-3 doubtful, 1-3 trusted but left out of the graph,
  // 3-4 trusted: scan 2 has only doubtful pairs, and scan 3's trusted pair
  // to 1 is not used, though its pair to 4 is.
  const std::vector<PairConstraint> constraints = {
      Pair(0, 1, 0.99), Pair(1, 2, kTrustedFrom - 0.01), Pair(2, 3, 0.1), Pair(1, 3, kTrustedFrom),
      Pair(3, 4, 1.0),
  };
  EXPECT_THAT(ScansWithoutTrustedPair(5, constraints, {true, true, true, false, true}),
              ::testing::ElementsAre(2));
  EXPECT_THAT(ScansWithoutTrustedPair(5, constraints, {true, true, true, false, false}),
              ::testing::ElementsAre(2, 3, 4));
  EXPECT_THAT(ScansWithoutTrustedPair(6, constraints, {true, true, true, true, true}),
              ::testing::ElementsAre(2, 5))
      << "a scan no pair touches has no trusted pair either";
}

TEST(UntrustedScans, NamesAndLineSayWhatHappensToThem) {
  EXPECT_EQ(UntrustedScansFromName("", "f"), UntrustedScans::kLeaveOut);
  EXPECT_EQ(UntrustedScansFromName(UntrustedScansName(UntrustedScans::kPlace), "f"),
            UntrustedScans::kPlace);
  EXPECT_THROW(UntrustedScansFromName("drop", "untrusted_scans"), InputError);

  std::vector<ScanSource> scans(3);
  scans[0].path = "/data/a.pcd";
  scans[1].path = "/data/b.pcd";
  scans[2].path = "c.pcd";
  EXPECT_EQ(UntrustedScansLine(scans, {}, true), "");
  EXPECT_EQ(UntrustedScansLine(scans, {0, 2}, true),
            "2 scans have no trusted pair; left out of the map (--untrusted-scans place fuses "
            "them): a.pcd, c.pcd");
  EXPECT_EQ(UntrustedScansLine(scans, {1}, false),
            "1 scan has no trusted pair; placed by the best doubtful pair: b.pcd");
}

}  // namespace
}  // namespace boicp
