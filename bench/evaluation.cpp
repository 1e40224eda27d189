#include "evaluation.hpp"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace boicp {
namespace {

std::vector<std::string> SplitCsvLine(const std::string& line) {
  std::vector<std::string> fields;
  std::stringstream stream(line);
  std::string field;
  while (std::getline(stream, field, ',')) fields.push_back(field);
  return fields;
}

double ParseNumber(const std::string& text, const std::string& where) {
  try {
    size_t used = 0;
    const double value = std::stod(text, &used);
    if (used == text.size() && std::isfinite(value)) return value;
  } catch (const std::exception&) {
  }
  throw InputError(where + ": '" + text + "' is not a number");
}

}  // namespace

std::vector<ReferencePair> ReadPairsCsv(const std::string& path) {
  std::ifstream file(path);
  if (!file) throw InputError(path + ": cannot open pairs file");
  const std::filesystem::path folder = std::filesystem::path(path).parent_path();
  std::string line;
  if (!std::getline(file, line) || line.rfind("source,target", 0) != 0) {
    throw InputError(path + ":1: expected header 'source,target,r00,...,t2'");
  }
  std::vector<ReferencePair> pairs;
  for (int number = 2; std::getline(file, line); ++number) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty()) continue;
    const std::string where = path + ":" + std::to_string(number);
    const std::vector<std::string> fields = SplitCsvLine(line);
    if (fields.size() != 14) {
      throw InputError(where + ": expected 14 columns, got " + std::to_string(fields.size()));
    }
    ReferencePair pair;
    pair.source = (folder / fields[0]).string();
    pair.target = (folder / fields[1]).string();
    for (int k = 0; k < 12; ++k)
      pair.T_target_source(k / 4, k % 4) = ParseNumber(fields[2 + k], where);
    pairs.push_back(pair);
  }
  if (pairs.empty()) throw InputError(path + ": no pairs");
  return pairs;
}

double RotationErrorDeg(const Transform& estimate, const Transform& reference) {
  return RotationAngle(estimate.inverse() * reference) * 180.0 / M_PI;
}

double TranslationErrorM(const Transform& estimate, const Transform& reference, const Point& at) {
  const Point moved_by_estimate =
      estimate.topLeftCorner<3, 3>() * at + estimate.topRightCorner<3, 1>();
  const Point moved_by_reference =
      reference.topLeftCorner<3, 3>() * at + reference.topRightCorner<3, 1>();
  return (moved_by_estimate - moved_by_reference).norm();
}

PerturbationKind ParsePerturbationKind(const std::string& name) {
  if (name == "none") return PerturbationKind::kNone;
  if (name == "yaw") return PerturbationKind::kYaw;
  if (name == "axis90") return PerturbationKind::kAxis90;
  if (name == "any") return PerturbationKind::kAnyRotation;
  throw InputError("unknown perturbation '" + name + "' (expected none, yaw, axis90 or any)");
}

std::string PerturbationKindName(PerturbationKind kind) {
  switch (kind) {
    case PerturbationKind::kNone:
      return "none";
    case PerturbationKind::kYaw:
      return "yaw";
    case PerturbationKind::kAxis90:
      return "axis90";
    case PerturbationKind::kAnyRotation:
      return "any";
  }
  return "none";
}

Transform RandomPerturbation(PerturbationKind kind, std::mt19937_64& rng) {
  Transform P = Transform::Identity();
  if (kind == PerturbationKind::kYaw) {
    std::uniform_real_distribution<double> angle(-M_PI, M_PI);
    P.topLeftCorner<3, 3>() =
        Eigen::AngleAxisd(angle(rng), Eigen::Vector3d::UnitZ()).toRotationMatrix();
  } else if (kind == PerturbationKind::kAxis90) {
    std::normal_distribution<double> gauss(0.0, 1.0);
    Eigen::Vector3d axis(gauss(rng), gauss(rng), gauss(rng));
    axis.normalize();
    std::uniform_real_distribution<double> angle(0.0, M_PI / 2);
    P.topLeftCorner<3, 3>() = Eigen::AngleAxisd(angle(rng), axis).toRotationMatrix();
  } else if (kind == PerturbationKind::kAnyRotation) {
    // A normalised 4-D Gaussian is a uniform unit quaternion.
    std::normal_distribution<double> gauss(0.0, 1.0);
    Eigen::Quaterniond q(gauss(rng), gauss(rng), gauss(rng), gauss(rng));
    P.topLeftCorner<3, 3>() = q.normalized().toRotationMatrix();
  }
  return P;
}

}  // namespace boicp
