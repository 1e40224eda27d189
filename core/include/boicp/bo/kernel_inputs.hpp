#pragma once
// How each coordinate of the unit box enters the surrogate's kernel, and the
// rotation-vector coordinates that let a search cover every rotation without
// gimbal lock.

#include <initializer_list>
#include <vector>

#include <Eigen/Core>

namespace boicp {

enum class InputKind {
  kLinear,    // distance |du|
  kPeriodic,  // an angle over the full circle: u = 0 and u = 1 are one point
  kRotation,  // one of three consecutive coordinates that form a rotation vector
};

/// The kind of every coordinate of a unit box. Rotation coordinates come in
/// aligned runs of three: u in [0,1]^3 stands for the rotation vector
/// (2u - 1) pi (RotationFromUnit), and the kernel sees the chordal distance
/// between the two rotations, a function of their geodesic angle alone. A run
/// has one length scale, its first coordinate's.
class KernelInputs {
 public:
  KernelInputs() = default;
  /// Throws InputError unless every kRotation is in an aligned run of three.
  explicit KernelInputs(std::vector<InputKind> kinds);
  /// kPeriodic where periodic[k], else kLinear. Implicit, so that a box of
  /// plain and periodic coordinates is written as `{false, true}`.
  KernelInputs(const std::vector<bool>& periodic);  // NOLINT(google-explicit-constructor)
  KernelInputs(std::initializer_list<bool> periodic);

  int dimension() const { return static_cast<int>(kinds_.size()); }
  bool empty() const { return kinds_.empty(); }
  InputKind operator[](int k) const { return kinds_[static_cast<size_t>(k)]; }
  /// Columns coordinate k adds to the kernel's embedding: 1 (linear), 2
  /// (periodic), 9 for the first coordinate of a rotation and 0 for the other two.
  int EmbeddedWidth(int k) const;
  /// True for the first coordinate of a rotation.
  bool StartsRotation(int k) const;
  /// True for the second and third coordinate of a rotation: their length
  /// scale is not used (the run's first one is).
  bool TiedLengthScale(int k) const { return EmbeddedWidth(k) == 0; }
  bool operator==(const KernelInputs& other) const { return kinds_ == other.kinds_; }

 private:
  std::vector<InputKind> kinds_;
};

/// The rotation whose rotation vector is (2u - 1) pi, for u in [0,1]^3.
Eigen::Matrix3d RotationFromUnit(const Eigen::Vector3d& u);

/// Unit coordinates of R's rotation vector, angle in [0, pi]: 0.5 + w / (2 pi).
/// Always inside the cube; RotationFromUnit(UnitFromRotation(R)) == R.
Eigen::Vector3d UnitFromRotation(const Eigen::Matrix3d& R);

}  // namespace boicp
