#include "boicp/registration/search_space.hpp"

#include <algorithm>
#include <cmath>

#include "boicp/registration/config.hpp"

namespace boicp {

Eigen::Matrix3d RotationFromEuler(double roll, double pitch, double yaw) {
  return (Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) *
          Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

Transform SearchSpace::ToTransform(const Eigen::VectorXd& u) const {
  Eigen::Matrix<double, 6, 1> value = Eigen::Matrix<double, 6, 1>::Zero();
  for (int k = 0; k < dimension(); ++k) {
    const int p = parameters[k];
    value[p] = (2.0 * u[k] - 1.0) * half_widths[p];
  }
  Transform offset = Transform::Identity();
  const Eigen::Matrix3d R = rotation_vector
                                ? RotationFromUnit(u.head<3>())
                                : RotationFromEuler(value[kRoll], value[kPitch], value[kYaw]);
  offset.topLeftCorner<3, 3>() = R;
  offset.topRightCorner<3, 1>() = pivot + value.tail<3>() - R * pivot;
  return offset * anchor;
}

Eigen::VectorXd SearchSpace::ToUnit(const Transform& T) const {
  const Transform offset = T * anchor.inverse();
  const Eigen::Matrix3d R = offset.topLeftCorner<3, 3>();
  Eigen::Matrix<double, 6, 1> value;
  value[kRoll] = std::atan2(R(2, 1), R(2, 2));
  value[kPitch] = std::asin(std::clamp(-R(2, 0), -1.0, 1.0));
  value[kYaw] = std::atan2(R(1, 0), R(0, 0));
  value.tail<3>() = offset.topRightCorner<3, 1>() - pivot + R * pivot;
  Eigen::VectorXd u(dimension());
  for (int k = 0; k < dimension(); ++k) {
    const int p = parameters[k];
    u[k] = std::clamp(0.5 + value[p] / (2.0 * half_widths[p]), 0.0, 1.0);
  }
  if (rotation_vector) u.head<3>() = UnitFromRotation(R);
  return u;
}

KernelInputs SearchSpace::Inputs() const {
  std::vector<InputKind> kinds;
  for (SearchParameter p : parameters) {
    if (rotation_vector && p <= kYaw) {
      kinds.push_back(InputKind::kRotation);
    } else {
      const bool periodic = (p == kRoll || p == kYaw) && half_widths[p] >= M_PI;
      kinds.push_back(periodic ? InputKind::kPeriodic : InputKind::kLinear);
    }
  }
  return KernelInputs(kinds);
}

SearchSpace MakeSearchSpace(const Transform& anchor, const Point& pivot,
                            const Eigen::Vector3d& rotation_half_widths,
                            const Eigen::Vector3d& translation_half_widths,
                            RotationCoordinates coordinates) {
  SearchSpace space;
  space.anchor = anchor;
  space.pivot = pivot;
  const Eigen::Vector3d rotation = SnapRotationBounds(rotation_half_widths);
  const bool every_rotation =
      rotation[kRoll] >= M_PI && rotation[kPitch] >= M_PI / 2 && rotation[kYaw] >= M_PI;
  space.rotation_vector = every_rotation && coordinates == RotationCoordinates::kRotationVector;
  space.half_widths << (space.rotation_vector ? Eigen::Vector3d::Constant(M_PI) : rotation),
      translation_half_widths;
  for (int p = kRoll; p <= kZ; ++p) {
    if (space.half_widths[p] > 0.0) space.parameters.push_back(static_cast<SearchParameter>(p));
  }
  return space;
}

}  // namespace boicp
