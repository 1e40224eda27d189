#pragma once
// Place recognition for scans that see all around (a spinning LiDAR): each
// scan is summarised by its Scan Context (Kim and Kim, IROS 2018), the
// highest point of each bin of a polar grid about the sensor's vertical
// axis. Two scans of one place then match whatever the chain between them
// has drifted, and the best column shift between them is their heading.

#include <Eigen/Core>

#include "boicp/util/point_span.hpp"
#include "boicp/util/types.hpp"

namespace boicp {

/// The grid of a place descriptor; the Scan Context paper's rings and sectors.
struct PlaceGrid {
  int rings = 20;            ///< radial bins out to max_radius
  int sectors = 60;          ///< azimuth bins, 6 degrees each
  double max_radius = 80.0;  ///< metres from the sensor; points beyond are left out
};

/// A scan's Scan Context; empty when the scan does not see all around.
struct PlaceDescriptor {
  /// rings x sectors: the highest point of each bin, metres above the
  /// scan's lowest points (its 1st percentile of height); 0 for an empty bin.
  Eigen::MatrixXf heights;
  /// Per ring, the share of its sectors that hold points: the same at any heading.
  Eigen::VectorXf ring_key;
  bool empty() const { return heights.size() == 0; }
};

/// Points must fill at least this share of the sectors for a scan to be
/// described: 240 degrees, the automatic settings' test of a scan that sees
/// all around. A depth camera's cone says nothing of the rest of its place.
constexpr double kPlaceMinSectorShare = 2.0 / 3.0;

/// Describes `points` (metres, the scan's frame, z up) about the vertical
/// through `sensor_origin`. Precondition: `grid`'s counts >= 1 and its
/// radius > 0.
PlaceDescriptor DescribePlace(PointSpan points, const Point& sensor_origin, const PlaceGrid& grid);

/// The radius that fits a scan: the 95th percentile of its points'
/// horizontal distance from `sensor_origin` (metres; 0 without points).
double PlaceRadius(PointSpan points, const Point& sensor_origin);

/// How alike two places look at their best relative heading.
struct PlaceMatch {
  /// One less the mean cosine between the columns both scans fill, at the
  /// best shift: 0 for one scan, about 0.5 and more for unrelated places;
  /// 1 when no column is filled in both.
  double distance = 1.0;
  /// Radians in (-pi, pi]: the rotation about z of T_target_source that
  /// brings the source's columns onto the target's, to one sector.
  double yaw = 0.0;
};

/// Compares every heading. Preconditions: both descriptors non-empty and
/// of one grid.
PlaceMatch MatchPlaces(const PlaceDescriptor& source, const PlaceDescriptor& target);

/// The T_target_source a place match suggests for scans whose sensors stood
/// at `source_origin` and `target_origin` (their frames): the match's yaw
/// about the sensors' vertical, the sensors on one spot.
Transform PlacePrior(const PlaceMatch& match, const Point& source_origin,
                     const Point& target_origin);

}  // namespace boicp
