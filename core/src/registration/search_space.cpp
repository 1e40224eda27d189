#include "boicp/registration/search_space.hpp"

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
  const Eigen::Matrix3d R = RotationFromEuler(value[kRoll], value[kPitch], value[kYaw]);
  offset.topLeftCorner<3, 3>() = R;
  offset.topRightCorner<3, 1>() = pivot + value.tail<3>() - R * pivot;
  return offset * anchor;
}

std::vector<bool> SearchSpace::Periodic() const {
  std::vector<bool> periodic;
  for (SearchParameter p : parameters) {
    periodic.push_back((p == kRoll || p == kYaw) && half_widths[p] >= M_PI);
  }
  return periodic;
}

SearchSpace MakeSearchSpace(const Transform& anchor, const Point& pivot,
                            const Eigen::Vector3d& rotation_half_widths,
                            const Eigen::Vector3d& translation_half_widths) {
  SearchSpace space;
  space.anchor = anchor;
  space.pivot = pivot;
  space.half_widths << SnapRotationBounds(rotation_half_widths), translation_half_widths;
  for (int p = kRoll; p <= kZ; ++p) {
    if (space.half_widths[p] > 0.0) space.parameters.push_back(static_cast<SearchParameter>(p));
  }
  return space;
}

}  // namespace boicp
