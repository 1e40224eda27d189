// PointSpan: points read where a caller keeps them (a vector of Points, or
// rows of a wider buffer of doubles) give the preprocessing and the
// automatic settings exactly what a copy into Points gives.

#include <vector>

#include <gtest/gtest.h>

#include "boicp/icp/preprocess.hpp"
#include "boicp/io/synthetic_scene.hpp"
#include "boicp/registration/auto_settings.hpp"
#include "boicp/util/point_span.hpp"

namespace boicp {
namespace {

// Bit for bit: EXPECT_EQ on doubles compares exactly.
void ExpectSamePoints(const Points& a, const Points& b) {
  ASSERT_EQ(a.size(), b.size());
  for (size_t i = 0; i < a.size(); ++i) ASSERT_EQ(a[i], b[i]) << "point " << i;
}

// Each point followed by three more numbers (a normal, say), as the first
// three columns of an (N, 6) array.
std::vector<double> RowsOfSix(const Points& points) {
  std::vector<double> rows;
  for (const Point& p : points) rows.insert(rows.end(), {p.x(), p.y(), p.z(), -1.0, -2.0, -3.0});
  return rows;
}

TEST(PointSpan, ViewsAVectorOfPointsInPlace) {
  const Points points = {{1.0, 2.0, 3.0}, {4.0, 5.0, 6.0}};
  const PointSpan span(points);
  ASSERT_EQ(span.size(), 2u);
  EXPECT_EQ(span[1], points[1]);
  ExpectSamePoints(span.ToPoints(), points);
  size_t visited = 0;
  for (const Point& p : span) EXPECT_EQ(p, points[visited++]);
  EXPECT_EQ(visited, 2u);
  EXPECT_TRUE(PointSpan(Points{}).empty());
}

TEST(PointSpan, RowsOfAWiderBufferPreprocessAsTheirCopy) {
  const Points street = MakeSyntheticStreet(3, 10.0);
  const std::vector<double> rows = RowsOfSix(street);
  const PointSpan span(rows.data(), street.size(), 6);
  ExpectSamePoints(span.ToPoints(), street);
  ExpectSamePoints(CropByRange(span, 2.0, 30.0), CropByRange(street, 2.0, 30.0));
  ExpectSamePoints(RandomSubsample(span, 500, 7), RandomSubsample(street, 500, 7));
  const CloudStatistics viewed = MeasureCloud(span, 5);
  const CloudStatistics copied = MeasureCloud(street, 5);
  EXPECT_EQ(viewed.rms_radius, copied.rms_radius);
  EXPECT_EQ(viewed.spacing, copied.spacing);
  EXPECT_EQ(viewed.far_returns, copied.far_returns);
}

}  // namespace
}  // namespace boicp
