// Scan Context place descriptors (core/mapping/place_recognition) and the
// loop candidates they find (LoopCandidatesFromPlaces).

#include <algorithm>
#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "boicp/io/synthetic_scene.hpp"
#include "boicp/mapping/loop_candidates.hpp"
#include "boicp/mapping/place_recognition.hpp"
#include "evaluation.hpp"

namespace boicp {
namespace {

constexpr double kSector = 2 * M_PI / 60;  // the default grid's sector, radians

double AngleBetween(double a, double b) { return std::abs(std::remainder(a - b, 2 * M_PI)); }

double YawOf(const Transform& T) { return std::atan2(T(1, 0), T(0, 0)); }

Points Turned(const Points& points, double yaw) {
  const Eigen::Matrix3d R = Eigen::AngleAxisd(yaw, Point::UnitZ()).toRotationMatrix();
  Points out;
  for (const Point& p : points) out.push_back(R * p);
  return out;
}

PlaceGrid GridFor(const Points& points) {
  PlaceGrid grid;
  grid.max_radius = PlaceRadius(points, Point::Zero());
  return grid;
}

// A scan turned about its sensor matches itself, and the match names the turn
// to within a sector (6 degrees).
TEST(PlaceRecognition, AScanTurnedMatchesItselfAndNamesTheTurn) {
  const Points scan = SyntheticDrive(1, 7).Scan(0).points;
  const PlaceGrid grid = GridFor(scan);
  const PlaceDescriptor source = DescribePlace(scan, Point::Zero(), grid);
  ASSERT_FALSE(source.empty());
  for (const double yaw : {0.0, 0.7, -2.5, 3.1}) {
    const PlaceDescriptor target = DescribePlace(Turned(scan, yaw), Point::Zero(), grid);
    const PlaceMatch match = MatchPlaces(source, target);
    EXPECT_LT(match.distance, 0.15) << yaw;
    EXPECT_LE(AngleBetween(match.yaw, yaw), kSector) << yaw;
    // The prior a match suggests turns the source onto the target.
    EXPECT_LE(AngleBetween(YawOf(PlacePrior(match, Point::Zero(), Point::Zero())), yaw), kSector);
    // Points cross sector borders as the scan turns, so its ring key moves a little.
    EXPECT_LT((target.ring_key - source.ring_key).cwiseAbs().maxCoeff(), 0.1) << yaw;
  }
  EXPECT_NEAR(MatchPlaces(source, source).distance, 0.0, 1e-6);
}

// Two metres on, a scan still looks like its place; thirty metres on, it does not.
TEST(PlaceRecognition, APlaceLooksMoreLikeItselfThanTheStreetFurtherOn) {
  const SyntheticDrive drive(16, 3);
  const Points first = drive.Scan(0).points;
  const PlaceGrid grid = GridFor(first);
  const PlaceDescriptor here = DescribePlace(first, Point::Zero(), grid);
  const double near =
      MatchPlaces(here, DescribePlace(drive.Scan(1).points, Point::Zero(), grid)).distance;
  const double far =
      MatchPlaces(here, DescribePlace(drive.Scan(15).points, Point::Zero(), grid)).distance;
  EXPECT_LT(near, far);
}

// A depth camera's cone says nothing of the rest of its place.
TEST(PlaceRecognition, ACameraConeIsNotDescribed) {
  Points cone;
  for (int i = 0; i < 2000; ++i) {
    const double azimuth = -0.5 + 1.0 * (i % 50) / 50.0, range = 1.0 + 0.1 * (i / 50);
    cone.push_back({range * std::cos(azimuth), range * std::sin(azimuth), 0.01 * (i % 7)});
  }
  EXPECT_TRUE(DescribePlace(cone, Point::Zero(), GridFor(cone)).empty());
  EXPECT_EQ(PlaceRadius(Points{}, Point::Zero()), 0.0);
}

// The sensor's origin is the grid's centre, and the prior keeps the sensors
// on one spot.
TEST(PlaceRecognition, TheSensorOriginCentresTheGridAndThePrior) {
  const Points scan = SyntheticDrive(1, 7).Scan(0).points;
  const Point origin(5.0, -2.0, 0.3);
  Points moved;
  for (const Point& p : scan) moved.push_back(p + origin);
  const PlaceGrid grid = GridFor(scan);
  const PlaceMatch match =
      MatchPlaces(DescribePlace(moved, origin, grid), DescribePlace(scan, Point::Zero(), grid));
  EXPECT_NEAR(match.distance, 0.0, 1e-6);
  const Transform prior = PlacePrior(match, origin, Point::Zero());
  const Point moved_origin = prior.topLeftCorner<3, 3>() * origin + prior.topRightCorner<3, 1>();
  EXPECT_TRUE(moved_origin.isZero(1e-9));
}

// A drive down the street, 3 m a scan, that turns and drives back over its
// own way (half a metre aside) for its last 10 scans: place recognition
// finds the returns, at their heading, and keeps the cap, the spacing and
// the budget.
class PlaceCandidatesOnALoop : public ::testing::Test {
 protected:
  static Transform Pose(int index) {
    if (index < 20) return PoseFromYawTranslation(0.02 * index, {-30.0 + 3.0 * index, 0.0, 1.8});
    const int station = 29 - index;  // scans 20..29 pass stations 9..0 again
    return PoseFromYawTranslation(M_PI + 0.03 * index, {-29.7 + 3.0 * station, 0.5, 1.8});
  }
  static void SetUpTestSuite() {
    const Points street = MakeSyntheticStreet(5);
    std::vector<Points> scans;
    for (int i = 0; i < kScans; ++i) {
      scans.push_back(SimulateScan(street, Pose(i), 35.0, 0.02, 100 + static_cast<uint64_t>(i)));
    }
    const PlaceGrid grid = GridFor(scans.front());
    places_ = new std::vector<PlaceDescriptor>();
    for (const Points& scan : scans) places_->push_back(DescribePlace(scan, Point::Zero(), grid));
  }
  static void TearDownTestSuite() { delete places_; }
  static std::vector<Point> Origins() { return std::vector<Point>(kScans, Point::Zero()); }
  // Every scan a piece of its own: nothing trusted connects any two.
  static std::vector<int> Apart() {
    std::vector<int> pieces(kScans);
    for (int i = 0; i < kScans; ++i) pieces[static_cast<size_t>(i)] = i;
    return pieces;
  }
  static constexpr int kScans = 30;
  static std::vector<PlaceDescriptor>* places_;
};
std::vector<PlaceDescriptor>* PlaceCandidatesOnALoop::places_ = nullptr;

TEST_F(PlaceCandidatesOnALoop, FindsReturnsAtTheirHeading) {
  LoopCandidateOptions options;
  options.max_place_per_drive_scan = 0.1;
  const std::vector<LoopCandidate> found =
      LoopCandidatesFromPlaces(*places_, Origins(), Apart(), {}, options);
  ASSERT_GE(found.size(), 2u) << "10 returns, candidates 5 apart";
  EXPECT_LE(found.size(), 3u) << "the budget: a tenth of 30 scans";
  // A street seen from 30 m further on, turned around, can look alike too:
  // candidates are proposals, which registration verifies.
  int returns = 0;
  for (const LoopCandidate& c : found) {
    EXPECT_EQ(c.found_by, LoopFoundBy::kPlace);
    EXPECT_GE(c.pair.source - c.pair.target, options.min_sequence_gap);
    const Transform truth = Pose(c.pair.target).inverse() * Pose(c.pair.source);
    const bool same_place = truth.topRightCorner<3, 1>().norm() < 2.0;
    returns += same_place && AngleBetween(YawOf(c.prior), YawOf(truth)) <= 2 * kSector;
  }
  EXPECT_GE(returns, 2);
  for (size_t a = 0; a < found.size(); ++a) {
    for (size_t b = a + 1; b < found.size(); ++b) {
      EXPECT_FALSE(std::abs(found[a].pair.source - found[b].pair.source) < options.min_spacing &&
                   std::abs(found[a].pair.target - found[b].pair.target) < options.min_spacing);
    }
  }
}

// The return as a second drive (scans 20-29): each drive has its own
// budget, pairs joining the drives are taken first, and the sequence gap
// holds within a drive only (scan 20 returns to scan 9, 11 scans back).
TEST_F(PlaceCandidatesOnALoop, ASecondDriveIsJoinedWhereItReturns) {
  LoopCandidateOptions options;
  options.min_sequence_gap = 15;
  options.min_spacing = 1;
  options.max_place_per_drive_scan = 0.1;
  std::vector<int> pieces(kScans, 0);
  for (int i = 20; i < kScans; ++i) pieces[static_cast<size_t>(i)] = 20;
  const std::vector<LoopCandidate> found =
      LoopCandidatesFromPlaces(*places_, Origins(), pieces, {}, options, {20});
  ASSERT_EQ(found.size(), 3u) << "the budgets: a tenth of 20 scans and of 10";
  for (const LoopCandidate& c : found) {
    EXPECT_GE(c.pair.source, 20);
    EXPECT_LT(c.pair.target, 20);
    const Transform truth = Pose(c.pair.target).inverse() * Pose(c.pair.source);
    EXPECT_LT((truth.topRightCorner<3, 1>().norm()), 2.0) << PairName(c.pair);
  }

  options.max_place_per_drive_scan = 1.0;
  const auto closest = [](const std::vector<LoopCandidate>& candidates) {
    int gap = 1000;
    for (const LoopCandidate& c : candidates) gap = std::min(gap, c.pair.source - c.pair.target);
    return gap;
  };
  EXPECT_LT(closest(LoopCandidatesFromPlaces(*places_, Origins(), pieces, {}, options, {20})), 15);
  EXPECT_GE(closest(LoopCandidatesFromPlaces(*places_, Origins(), pieces, {}, options)), 15)
      << "one drive";
}

TEST_F(PlaceCandidatesOnALoop, StaysClearOfPairsAlreadyTaken) {
  LoopCandidateOptions options;
  options.max_place_per_drive_scan = 1.0;
  const std::vector<LoopCandidate> all =
      LoopCandidatesFromPlaces(*places_, Origins(), Apart(), {}, options);
  ASSERT_FALSE(all.empty());
  const PairIndex taken = all.front().pair;
  for (const LoopCandidate& c :
       LoopCandidatesFromPlaces(*places_, Origins(), Apart(), {taken}, options)) {
    EXPECT_FALSE(std::abs(c.pair.source - taken.source) < options.min_spacing &&
                 std::abs(c.pair.target - taken.target) < options.min_spacing)
        << PairName(c.pair);
  }
}

// Scans that trusted pairs already connect are placed by the chain: place
// recognition only joins pieces.
TEST_F(PlaceCandidatesOnALoop, JoinsOnlyScansOfDifferentPieces) {
  LoopCandidateOptions options;
  options.max_place_per_drive_scan = 1.0;
  const std::vector<int> one_piece(kScans, 0);
  EXPECT_TRUE(LoopCandidatesFromPlaces(*places_, Origins(), one_piece, {}, options).empty());
  std::vector<int> split(kScans, 0);
  std::fill(split.begin() + 20, split.end(), 20);  // the way back is a piece of its own
  const std::vector<LoopCandidate> found =
      LoopCandidatesFromPlaces(*places_, Origins(), split, {}, options);
  ASSERT_FALSE(found.empty());
  for (const LoopCandidate& c : found) {
    EXPECT_GE(c.pair.source, 20) << PairName(c.pair);
    EXPECT_LT(c.pair.target, 20) << PairName(c.pair);
  }
}

TEST(PlaceCandidates, NoDescriptorsNoCandidates) {
  const std::vector<PlaceDescriptor> none(30);
  std::vector<int> pieces(30);
  for (int i = 0; i < 30; ++i) pieces[static_cast<size_t>(i)] = i;
  EXPECT_TRUE(LoopCandidatesFromPlaces(none, std::vector<Point>(30, Point::Zero()), pieces, {}, {})
                  .empty());
  EXPECT_EQ(LoopFoundByName(LoopFoundBy::kPlace), "place");
  EXPECT_EQ(LoopFoundByName(LoopFoundBy::kPoses), "poses");
}

}  // namespace
}  // namespace boicp
