// The fitted confidence model keeps the direction each feature must have,
// whatever a refit does to its weights.

#include <gtest/gtest.h>

#include "boicp/registration/bo_icp.hpp"
#include "boicp/registration/confidence.hpp"

namespace boicp {
namespace {

ConfidenceFeatures Features(double fitness, double margin, double resolution_deg) {
  ConfidenceFeatures f;
  f.fitness = fitness;
  f.margin = margin;
  f.resolution_deg = resolution_deg;
  return f;
}

// Confidence rises with every inlier, whatever the margin and resolution.
TEST(Confidence, MonotoneInFitness) {
  for (double margin : {0.0, 0.1, 1.0}) {
    for (double resolution : {0.1, 1.0}) {
      double previous = -1.0;
      for (double fitness = 0.0; fitness <= 1.0; fitness += 0.05) {
        const double c = Confidence(Features(fitness, margin, resolution));
        EXPECT_GT(c, previous) << fitness << " " << margin << " " << resolution;
        previous = c;
      }
    }
  }
}

// No inliers (RefineCoarseToFine then reports no margin either) is never
// trusted, at any resolution; nor is a weak fit without a runner-up.
TEST(Confidence, NoInliersOrAWeakLoneAnswerIsDoubtful) {
  for (double resolution : {0.05, 0.5, 2.0}) {
    EXPECT_EQ(Confidence(Features(0.0, 0.0, resolution)), 0.0);
    EXPECT_LT(Confidence(Features(0.2, 0.0, resolution)), kTrustedFrom);
  }
}

// A street scan registered onto a room matched 0.1 % of its points, and its
// runner-up matched a seventh of that: a wide relative margin between two
// empty fits. Few matches are doubtful whatever the margin and resolution.
TEST(Confidence, AnAnswerAlmostNothingMatchesIsDoubtfulWhateverItsMargin) {
  for (double fitness : {0.001, 0.02, 0.049}) {
    for (double margin : {0.857, 1.0}) {
      for (double resolution : {0.0, 0.015, 0.5}) {
        EXPECT_LT(Confidence(Features(fitness, margin, resolution)), kTrustedFrom)
            << fitness << " " << margin << " " << resolution;
      }
    }
  }
}

TEST(Confidence, MoreInliersAndAWiderMarginAreMoreCertain) {
  EXPECT_LT(Confidence(Features(0.3, 0.5, 0.5)), Confidence(Features(0.6, 0.5, 0.5)));
  EXPECT_LT(Confidence(Features(0.3, 0.05, 0.5)), Confidence(Features(0.3, 0.6, 0.5)));
  for (double fitness : {0.01, 0.3, 1.0}) {
    const double c = Confidence(Features(fitness, 1.0, 0.2));
    EXPECT_GT(c, 0.0);
    EXPECT_LT(c, 1.0);
  }
}

// The bunny's answer at the fixed settings (a 2.5 mm refinement voxel, 2.4
// degrees at its RMS radius) ends 2.1 degrees off with the same fit as a
// right one; at the automatic 0.56 mm voxel (0.57 degrees) it is right.
TEST(Confidence, AFitAtTooCoarseARefinementVoxelIsDoubtful) {
  EXPECT_LT(Confidence(Features(0.506, 0.315, 2.37)), 0.5);
  EXPECT_GT(Confidence(Features(0.506, 0.315, 0.57)), 0.5);
}

// A 7-Scenes pair slid along a wall it half overlaps, and a generated street
// turned 180 degrees: another basin fits almost as well. The right answer of
// that 7-Scenes pair has a margin of 13-15 %.
TEST(Confidence, ANearTieIsDoubtful) {
  EXPECT_LT(Confidence(Features(0.29, 0.02, 0.48)), 0.5);
  EXPECT_LT(Confidence(Features(0.39, 0.024, 0.49)), 0.5);
  EXPECT_GT(Confidence(Features(0.355, 0.13, 0.48)), 0.5);
  EXPECT_GT(Confidence(Features(0.36, 0.6, 0.48)), 0.5);
}

ConfidenceFeatures Measured(ConfidenceFeatures f) {
  f.margin_measured = true;
  return f;
}

// Two basins within 2 % of each other's fitness are a tie whatever the fit:
// a 7-Scenes pair's wrong answer fitted 39 % of its points with its runner-up
// 1.4 % behind. Trust never falls as a measured margin widens, and a margin
// nothing was compared with (a lone start) is left to the model.
TEST(Confidence, AMeasuredNearTieIsDoubtfulWhateverItsFit) {
  for (double fitness : {0.394, 0.7, 1.0}) {
    for (double margin : {0.0, 0.01, 0.014, 0.019}) {
      EXPECT_LT(Confidence(Measured(Features(fitness, margin, 0.2))), kTrustedFrom)
          << fitness << " " << margin;
    }
    EXPECT_EQ(Confidence(Measured(Features(fitness, 0.01, 0.2))), 0.0);
    double previous = 0.0;
    for (double margin = 0.0; margin <= 1.0; margin += 0.005) {
      const double c = Confidence(Measured(Features(fitness, margin, 0.2)));
      EXPECT_GE(c, previous) << fitness << " " << margin;
      previous = c;
    }
    EXPECT_EQ(Confidence(Measured(Features(fitness, 0.5, 0.2))),
              Confidence(Features(fitness, 0.5, 0.2)));
  }
  EXPECT_GT(Confidence(Features(0.8, 0.0, 0.2)), kTrustedFrom);
}

ConfidenceFeatures SeenThrough(ConfidenceFeatures f, double seen_through) {
  f.seen_through = seen_through;
  return f;
}

// Trust never rises as more of the answer's points land where the target's
// sensor saw through, and a right answer's few per cent (what moved between
// the scans) cost nothing.
TEST(Confidence, FallsWithTheShareSeenThrough) {
  for (const ConfidenceFeatures& f :
       {Features(0.7, 0.9, 0.2), Features(0.36, 0.6, 0.48), Features(0.2, 1.0, 0.5)}) {
    EXPECT_EQ(Confidence(SeenThrough(f, 0.1)), Confidence(f));
    double previous = Confidence(f);
    for (double share = 0.0; share <= 1.0; share += 0.02) {
      const double c = Confidence(SeenThrough(f, share));
      EXPECT_LE(c, previous) << share;
      previous = c;
    }
    EXPECT_EQ(Confidence(SeenThrough(f, 0.3)), 0.0);
  }
}

// Wrong answers the other features trusted: a KITTI street turned 164
// degrees with a sector cut from the source, and a bunny scan turned 153
// degrees; each put over a third of its points in front of the target's
// returns. Their fits and margins alone look right.
TEST(Confidence, AnAnswerSeenThroughIsDoubtfulWhateverItsFit) {
  const ConfidenceFeatures street = Features(0.109, 0.43, 0.213);
  const ConfidenceFeatures bunny = Features(0.184, 0.818, 0.572);
  EXPECT_GT(Confidence(street), 0.5);
  EXPECT_GT(Confidence(bunny), 0.5);
  EXPECT_LT(Confidence(SeenThrough(street, 0.353)), kTrustedFrom);
  EXPECT_LT(Confidence(SeenThrough(bunny, 0.381)), kTrustedFrom);
}

// An answer free to slide or turn (a corridor, a floor) is doubtful whatever
// its fit and margin; one that holds its weakest direction loses nothing.
TEST(Confidence, AnAnswerFreeAlongSomeDirectionIsDoubtful) {
  for (const ConfidenceFeatures& held :
       {Features(0.9, 1.0, 0.1), Features(0.5, 0.6, 0.3), Features(0.3, 0.2, 0.5)}) {
    ConfidenceFeatures f = held;
    f.constrained_share = 0.03;
    EXPECT_EQ(Confidence(f), Confidence(held));
    double previous = Confidence(f);
    for (double share = 0.03; share >= 0.0; share -= 0.001) {
      f.constrained_share = share;
      EXPECT_LE(Confidence(f), previous) << share;
      previous = Confidence(f);
    }
    f.constrained_share = 0.5 * kUnconstrainedShare;
    EXPECT_EQ(Confidence(f), 0.0);
    f.constrained_share = 0.99 * kUnconstrainedShare;  // any unconstrained direction
    EXPECT_LT(Confidence(f), kTrustedFrom);
  }
}

// An answer whose fit a slide off it keeps (a street of look-alike
// stretches) is doubtful however well it fits, and trusted at none from
// 0.92 on; at 0.88 or under, or unmeasured, it loses nothing.
TEST(Confidence, AnAnswerWhoseFitASlideKeepsIsDoubtful) {
  const ConfidenceFeatures best_fit = Features(0.9, 1.0, 0.1);
  ASSERT_GT(Confidence(best_fit), 0.999);
  ConfidenceFeatures f = best_fit;
  f.slide_rival = 0.88;
  EXPECT_EQ(Confidence(f), Confidence(best_fit));
  f.slide_rival = 0.9;
  EXPECT_LT(Confidence(f), kTrustedFrom);
  for (const double rival : {0.92, 1.1}) {  // 1.1: a slide fits better than the answer
    f.slide_rival = rival;
    EXPECT_EQ(Confidence(f), 0.0) << rival;
  }
}

}  // namespace
}  // namespace boicp
