#pragma once
// Accuracy evaluation against reference transforms: the pairs.csv format of
// the shared data, error metrics, and the seeded perturbations that move the
// truth away from identity.

#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include "boicp/util/types.hpp"

namespace boicp {

/// One row of a pairs.csv: `source,target,r00,r01,r02,t0,r10,...,t2`, paths
/// relative to the CSV's folder (resolved to full paths here), and the
/// row-major 3x4 of T_target_source.
struct ReferencePair {
  std::string source;
  std::string target;
  Transform T_target_source = Transform::Identity();
};

/// Reads every row; throws InputError naming the file and line for a missing
/// header, a wrong number of columns or a non-numeric entry.
std::vector<ReferencePair> ReadPairsCsv(const std::string& path);

/// Angle of R_est^T R_ref, in degrees.
double RotationErrorDeg(const Transform& estimate, const Transform& reference);

/// |estimate * at - reference * at|, metres: the translation error at the
/// point `at` of the source frame (its origin by default).
double TranslationErrorM(const Transform& estimate, const Transform& reference,
                         const Point& at = Point::Zero());

enum class PerturbationKind {
  kNone,         // identity
  kYaw,          // rotation about z by a uniform angle in [-pi, pi] (ground vehicles)
  kAxis90,       // uniform random axis, uniform angle in [0, 90 degrees]
  kAnyRotation,  // uniform over all rotations
};

/// "none" | "yaw" | "axis90" | "any"
PerturbationKind ParsePerturbationKind(const std::string& name);
std::string PerturbationKindName(PerturbationKind kind);

/// A rotation about the sensor origin drawn as `kind` describes. Apply it to
/// the source scan (p' = P p); the expected transform becomes T_ref * P^-1.
Transform RandomPerturbation(PerturbationKind kind, std::mt19937_64& rng);

}  // namespace boicp
