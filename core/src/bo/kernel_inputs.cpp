#include "boicp/bo/kernel_inputs.hpp"

#include <cmath>
#include <string>
#include <utility>

#include <Eigen/Geometry>

#include "boicp/util/types.hpp"

namespace boicp {
namespace {

// Index of coordinate k within its run of rotation coordinates.
int PlaceInRun(const std::vector<InputKind>& kinds, int k) {
  int place = 0;
  for (int j = k - 1; j >= 0 && kinds[static_cast<size_t>(j)] == InputKind::kRotation; --j) {
    ++place;
  }
  return place % 3;
}

}  // namespace

KernelInputs::KernelInputs(std::vector<InputKind> kinds) : kinds_(std::move(kinds)) {
  int run = 0;
  for (size_t k = 0; k <= kinds_.size(); ++k) {
    if (k < kinds_.size() && kinds_[k] == InputKind::kRotation) {
      ++run;
      continue;
    }
    if (run % 3 != 0) {
      throw InputError("KernelInputs: rotation coordinates come in runs of three, got a run of " +
                       std::to_string(run));
    }
    run = 0;
  }
}

KernelInputs::KernelInputs(const std::vector<bool>& periodic) {
  for (bool p : periodic) kinds_.push_back(p ? InputKind::kPeriodic : InputKind::kLinear);
}

KernelInputs::KernelInputs(std::initializer_list<bool> periodic)
    : KernelInputs(std::vector<bool>(periodic)) {}

int KernelInputs::EmbeddedWidth(int k) const {
  switch ((*this)[k]) {
    case InputKind::kLinear:
      return 1;
    case InputKind::kPeriodic:
      return 2;
    case InputKind::kRotation:
      return PlaceInRun(kinds_, k) == 0 ? 9 : 0;
  }
  return 1;
}

bool KernelInputs::StartsRotation(int k) const {
  return (*this)[k] == InputKind::kRotation && PlaceInRun(kinds_, k) == 0;
}

Eigen::Matrix3d RotationFromUnit(const Eigen::Vector3d& u) {
  const Eigen::Vector3d w = (2.0 * u.array() - 1.0).matrix() * M_PI;
  const double angle = w.norm();
  if (angle < 1e-12) return Eigen::Matrix3d::Identity();
  return Eigen::AngleAxisd(angle, w / angle).toRotationMatrix();
}

Eigen::Vector3d UnitFromRotation(const Eigen::Matrix3d& R) {
  const Eigen::AngleAxisd aa(R);
  const Eigen::Vector3d w = aa.angle() * aa.axis();
  return (0.5 + w.array() / (2.0 * M_PI)).matrix();
}

}  // namespace boicp
