// Plain-text files: XYZ point lists and rigid transforms.

#include <algorithm>
#include <charconv>
#include <cmath>
#include <string_view>

#include "io/io_readers.hpp"

namespace boicp {

namespace io_detail {

namespace {

constexpr double kOrthonormalTolerance = 1e-3;
constexpr double kBottomRowTolerance = 1e-9;
constexpr size_t kQuotedLineLimit = 60;

// Keeps error messages one short line even for binary junk read as text.
std::string Quoted(const std::string& line) {
  if (line.size() <= kQuotedLineLimit) return "'" + line + "'";
  return "'" + line.substr(0, kQuotedLineLimit) + "...'";
}

// Reads x y z from the first three fields (IsFieldSeparator); later columns
// (intensity, colour, labels) may hold anything and are ignored. Allocates
// nothing unless the line is bad, and tests each character once: a scan has
// hundreds of thousands of lines.
Point ParseXyzLine(std::string_view line, const std::string& path, size_t line_number) {
  Point point;
  const char* next = line.data();
  const char* const end = next + line.size();
  for (Eigen::Index i = 0; i < 3; ++i) {
    while (next != end && IsFieldSeparator(*next)) ++next;
    const char* const token = next;
    while (next != end && !IsFieldSeparator(*next)) ++next;
    const std::optional<double> value =
        token == end ? std::nullopt
                     : ParseNumber(std::string_view(token, static_cast<size_t>(next - token)));
    if (!value) {
      throw InputError(path + ":" + std::to_string(line_number) +
                       ": expected at least 3 numbers (x y z), got " + Quoted(std::string(line)));
    }
    point[i] = *value;
  }
  return point;
}

Transform TransformFromNumbers(const std::string& path, const std::vector<double>& numbers) {
  if (numbers.size() != 12 && numbers.size() != 16) {
    throw InputError(path + ": expected 12 (3x4) or 16 (4x4) numbers for a transform, got " +
                     std::to_string(numbers.size()));
  }
  for (double value : numbers) {
    if (!std::isfinite(value)) throw InputError(path + ": transform holds a non-finite number");
  }
  Transform T = Transform::Identity();
  const size_t rows = numbers.size() / 4;
  for (size_t r = 0; r < rows; ++r) {
    for (size_t c = 0; c < 4; ++c) {
      T(static_cast<Eigen::Index>(r), static_cast<Eigen::Index>(c)) = numbers[r * 4 + c];
    }
  }
  return T;
}

// Shortest text that reads back as exactly the same double.
void AppendNumber(double value, std::string* out) {
  char buffer[32];
  const auto result = std::to_chars(buffer, buffer + sizeof(buffer), value);
  out->append(buffer, result.ptr);
}

}  // namespace

uint64_t CountDataLines(const std::string& path) {
  std::ifstream in = OpenOrThrow(path);
  uint64_t count = 0;
  std::string line;
  while (std::getline(in, line)) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    count += IsBlankOrComment(line) ? 0 : 1;
  }
  if (in.bad()) throw InputError(path + ": read error");
  return count;
}

Points ReadXyzText(const std::string& path, uint64_t max_points) {
  // Text declares no count: the lines are counted before any point is kept.
  const uint64_t count = CountDataLines(path);
  RequirePointCount(path, count, max_points);
  std::ifstream in = OpenOrThrow(path);
  Points points;
  points.reserve(static_cast<size_t>(count));
  std::string line;
  for (size_t line_number = 1; std::getline(in, line); ++line_number) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (IsBlankOrComment(line)) continue;
    points.push_back(ParseXyzLine(line, path, line_number));
  }
  if (in.bad()) throw InputError(path + ": read error");
  return points;
}

}  // namespace io_detail

Transform ReadTransformFile(const std::string& path) {
  const Transform T = io_detail::TransformFromNumbers(path, io_detail::ReadNumbersFile(path));
  RequireRigidTransform(path, T);
  return T;
}

void RequireRigidTransform(const std::string& path, const Transform& T) {
  const Eigen::Vector4d bottom = T.row(3).transpose();
  if ((bottom - Eigen::Vector4d(0, 0, 0, 1)).cwiseAbs().maxCoeff() >
      io_detail::kBottomRowTolerance) {
    throw InputError(path + ": last row of a 4x4 transform must be 0 0 0 1");
  }
  const Eigen::Matrix3d R = T.topLeftCorner<3, 3>();
  const double error = (R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
  if (error > io_detail::kOrthonormalTolerance) {
    throw InputError(path + ": rotation part is not orthonormal (max |R^T R - I| = " +
                     std::to_string(error) + ", tolerance 1e-3)");
  }
  // An orthonormal matrix with determinant -1 is a reflection, not a motion.
  if (R.determinant() < 0.0) {
    throw InputError(path + ": rotation part is a reflection (determinant -1)");
  }
}

void WriteXyz(const std::string& path, const Points& points) {
  std::ofstream out(path);
  if (!out) throw InputError(path + ": cannot open for writing");
  std::string line;
  for (const Point& p : points) {
    line.clear();
    io_detail::AppendNumber(p.x(), &line);
    line += ' ';
    io_detail::AppendNumber(p.y(), &line);
    line += ' ';
    io_detail::AppendNumber(p.z(), &line);
    line += '\n';
    out << line;
  }
  out.close();
  if (!out) throw InputError(path + ": write error");
}

}  // namespace boicp
