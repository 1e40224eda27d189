#include "boicp/io/trajectory_io.hpp"

#include <fstream>
#include <iomanip>
#include <ostream>

#include "io/io_readers.hpp"

namespace boicp {
namespace {

// Enough digits that a pose read back is the same double pose to ~1e-12.
constexpr int kDigits = 12;

std::vector<std::vector<double>> ReadRows(const std::string& path, size_t columns,
                                          const std::string& kind) {
  std::ifstream in = io_detail::OpenOrThrow(path);
  std::vector<std::vector<double>> rows;
  std::string line;
  for (int number = 1; std::getline(in, line); ++number) {
    if (io_detail::IsBlankOrComment(line)) continue;
    const auto fields = io_detail::SplitFields(line);
    const std::string where = path + ":" + std::to_string(number) + ": ";
    if (fields.size() != columns) {
      throw InputError(where + kind + " lines have " + std::to_string(columns) + " numbers, not " +
                       std::to_string(fields.size()));
    }
    std::vector<double> row;
    for (const auto& field : fields) {
      const auto value = io_detail::ParseNumber(field);
      if (!value) throw InputError(where + "'" + std::string(field) + "' is not a number");
      row.push_back(*value);
    }
    rows.push_back(std::move(row));
  }
  return rows;
}

}  // namespace

void WriteTumTrajectory(std::ostream& out, const std::vector<double>& timestamps,
                        const std::vector<Transform>& poses) {
  if (timestamps.size() != poses.size()) {
    throw InputError("TUM trajectory: " + std::to_string(timestamps.size()) + " timestamps for " +
                     std::to_string(poses.size()) + " poses");
  }
  out << std::setprecision(kDigits);
  for (size_t i = 0; i < poses.size(); ++i) {
    const Eigen::Quaterniond q(Eigen::Matrix3d(poses[i].topLeftCorner<3, 3>()));
    const Eigen::Vector3d t = poses[i].topRightCorner<3, 1>();
    out << std::fixed << std::setprecision(6) << timestamps[i] << std::defaultfloat
        << std::setprecision(kDigits) << " " << t.x() << " " << t.y() << " " << t.z() << " "
        << q.x() << " " << q.y() << " " << q.z() << " " << q.w() << "\n";
  }
}

void WriteKittiTrajectory(std::ostream& out, const std::vector<Transform>& poses) {
  out << std::setprecision(kDigits);
  for (const Transform& T : poses) {
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 4; ++c) out << (r + c > 0 ? " " : "") << T(r, c);
    }
    out << "\n";
  }
}

std::vector<TimedPose> ReadTumTrajectory(const std::string& path) {
  std::vector<TimedPose> poses;
  for (const auto& row : ReadRows(path, 8, "TUM trajectory")) {
    TimedPose p;
    p.timestamp = row[0];
    const Eigen::Quaterniond q(row[7], row[4], row[5], row[6]);
    p.pose.topLeftCorner<3, 3>() = q.normalized().toRotationMatrix();
    p.pose.topRightCorner<3, 1>() = Eigen::Vector3d(row[1], row[2], row[3]);
    poses.push_back(p);
  }
  return poses;
}

std::vector<Transform> ReadKittiTrajectory(const std::string& path) {
  std::vector<Transform> poses;
  for (const auto& row : ReadRows(path, 12, "KITTI trajectory")) {
    Transform T = Transform::Identity();
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 4; ++c) T(r, c) = row[static_cast<size_t>(4 * r + c)];
    }
    poses.push_back(T);
  }
  return poses;
}

}  // namespace boicp
