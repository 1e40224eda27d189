#pragma once
// Field conditions: what real logs do to a clean benchmark pair (far
// returns, an occluded sector, a sparser sensor, a tilted mount), applied to
// the loaded scans so that the confidence is tried on answers that can fail
// in the ways field data makes them fail.

#include <cstdint>
#include <string>

#include "boicp/util/types.hpp"

namespace boicp::bench {

enum class FieldCondition {
  kClean,
  kFarReturns,  // 3 % extra returns in both, 15 to 40 RMS radii out
  kSector,      // a 90 degree azimuth sector removed from the source
  kQuarter,     // the source at a quarter of its density
  kTilt,        // the source sensor tilted by 25 degrees
  kFarOrigin,   // both scans 1 km from their frame's origin (a site frame)
  kGeoOrigin,   // both scans at UTM-like coordinates, 5.4e6 m from the origin
};

FieldCondition ParseFieldCondition(const std::string& name);  // throws InputError
std::string FieldConditionName(FieldCondition condition);
/// Every name ParseFieldCondition accepts, "|"-separated.
std::string FieldConditionNames();

/// The scans of one pair after a condition, and the rigid motions it gave
/// each scan's frame (identity when it only removed or added points).
struct FieldPair {
  Points source, target;
  Transform source_motion = Transform::Identity();  // p -> source_motion * p
  Transform target_motion = Transform::Identity();

  /// T_target_source of these scans with the source moved by `perturbation`
  /// P afterwards, from the clean pair's T: target_motion * T *
  /// source_motion^-1 * P^-1.
  Transform Expected(const Transform& T_target_source, const Transform& perturbation) const;
  /// Where the translation error is measured in the perturbed source's frame:
  /// the source's own origin as the condition moved it, rotated by P (0 for
  /// a clean pair), so that scans 1 km from their frame's origin do not read
  /// a right answer's 0.1 degrees as metres.
  Point ErrorPoint(const Transform& perturbation) const;
};

/// Applies `condition` to a loaded pair; the random choices (which points,
/// which sector, where the extra returns go) follow `seed`.
FieldPair ApplyFieldCondition(FieldCondition condition, Points source, Points target,
                              uint64_t seed);

}  // namespace boicp::bench
