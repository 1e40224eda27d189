#pragma once
// The box that BO searches, and how a point of it becomes an initial transform.

#include <vector>

#include <Eigen/Core>

#include "boicp/bo/kernel_inputs.hpp"
#include "boicp/registration/config.hpp"
#include "boicp/util/types.hpp"

namespace boicp {

/// Rotation R = Rz(yaw) Ry(pitch) Rx(roll), radians.
Eigen::Matrix3d RotationFromEuler(double roll, double pitch, double yaw);

/// Indices into the six search parameters (roll, pitch, yaw, x, y, z).
enum SearchParameter { kRoll = 0, kPitch, kYaw, kX, kY, kZ };

/// Maps the unit box [0,1]^d onto initial transforms around an anchor:
///   T0(u) = Trans(pivot + delta) * R(roll, pitch, yaw) * Trans(-pivot) * anchor,
/// where each searched parameter is (2 u_k - 1) * half_width and the others
/// are zero. u = 0.5 everywhere gives the anchor itself. Rotating about the
/// pivot (the anchor-mapped source centroid) instead of the sensor origin keeps
/// a rotated depth view over the same part of the scene. With
/// `rotation_vector`, the three rotation parameters are instead the unit
/// coordinates of a rotation vector (RotationFromUnit), half-width pi.
struct SearchSpace {
  Transform anchor = Transform::Identity();
  Point pivot = Point::Zero();              // in the target frame
  std::vector<SearchParameter> parameters;  // what each unit coordinate controls
  Eigen::Matrix<double, 6, 1> half_widths = Eigen::Matrix<double, 6, 1>::Zero();
  bool rotation_vector = false;

  int dimension() const { return static_cast<int>(parameters.size()); }
  Transform ToTransform(const Eigen::VectorXd& u) const;
  /// The unit coordinates whose transform comes closest to T: T's offset from
  /// the anchor as Euler angles (pitch in [-pi/2, pi/2]) or a rotation vector
  /// and a translation of the pivot, each clamped into the box. Parameters the box does not search
  /// are dropped, so ToTransform(ToUnit(T)) == T only for T inside the box.
  Eigen::VectorXd ToUnit(const Transform& T) const;

  /// Roll and yaw wrap around when their half-width reaches pi; a rotation
  /// vector is one kernel input of three coordinates.
  KernelInputs Inputs() const;
};

/// The rotation-stage, translation-stage or joint box with non-zero
/// half-widths only (parameters whose half-width is zero are not searched).
/// `coordinates` applies when the rotation bounds hold every rotation (roll
/// and yaw pi, pitch pi/2); a narrower box is always in Euler angles.
SearchSpace MakeSearchSpace(const Transform& anchor, const Point& pivot,
                            const Eigen::Vector3d& rotation_half_widths,
                            const Eigen::Vector3d& translation_half_widths,
                            RotationCoordinates coordinates = RotationCoordinates::kEulerAngles);

}  // namespace boicp
