#include "ros_message_writer.hpp"

#include <cstring>
#include <limits>
#include <stdexcept>

namespace boicp::test {
namespace {

// The mirror of io_detail::MessageCursor: ROS 1 packed little-endian, or CDR
// with its encapsulation header and natural alignment.
class MessageWriter {
 public:
  MessageWriter(MessageEncoding encoding, bool big_endian)
      : encoding_(encoding), big_endian_(encoding == MessageEncoding::kCdr && big_endian) {
    if (encoding_ == MessageEncoding::kCdr) {
      bytes_ = {0, static_cast<uint8_t>(big_endian_ ? 0 : 1), 0, 0};
      origin_ = 4;
    }
  }

  void U8(uint8_t value) { Primitive(value, 1); }
  void U32(uint32_t value) { Primitive(value, 4); }
  void I32(int32_t value) {
    uint32_t bits;
    std::memcpy(&bits, &value, sizeof bits);
    U32(bits);
  }
  void F64(double value) {
    uint64_t bits;
    std::memcpy(&bits, &value, sizeof bits);
    Primitive(bits, 8);
  }
  void String(const std::string& value) {
    const bool cdr = encoding_ == MessageEncoding::kCdr;
    U32(static_cast<uint32_t>(value.size() + (cdr ? 1 : 0)));
    bytes_.insert(bytes_.end(), value.begin(), value.end());
    if (cdr) bytes_.push_back(0);
  }
  void Bytes(const std::vector<uint8_t>& value) {
    U32(static_cast<uint32_t>(value.size()));
    bytes_.insert(bytes_.end(), value.begin(), value.end());
  }
  void Header(int64_t stamp_ns, const std::string& frame_id) {
    const int64_t sec = stamp_ns / 1000000000;
    const uint32_t nsec = static_cast<uint32_t>(stamp_ns % 1000000000);
    if (encoding_ == MessageEncoding::kRos1) {
      U32(7);  // seq
      U32(static_cast<uint32_t>(sec));
    } else {
      I32(static_cast<int32_t>(sec));
    }
    U32(nsec);
    String(frame_id);
  }

  std::vector<uint8_t> Take() { return std::move(bytes_); }

 private:
  void Primitive(uint64_t value, size_t width) {
    if (encoding_ == MessageEncoding::kCdr) {
      while ((bytes_.size() - origin_) % width != 0) bytes_.push_back(0);
    }
    for (size_t i = 0; i < width; ++i) {
      const size_t shift = big_endian_ ? (width - 1 - i) : i;
      bytes_.push_back(static_cast<uint8_t>(value >> (8 * shift)));
    }
  }

  MessageEncoding encoding_;
  bool big_endian_;
  size_t origin_ = 0;
  std::vector<uint8_t> bytes_;
};

constexpr uint8_t kFloat32 = 7;
constexpr uint8_t kFloat64 = 8;

void PutScalar(uint8_t* at, uint64_t bits, size_t width, bool big_endian) {
  for (size_t i = 0; i < width; ++i) {
    const size_t shift = big_endian ? (width - 1 - i) : i;
    at[i] = static_cast<uint8_t>(bits >> (8 * shift));
  }
}

void PutCoordinate(uint8_t* at, double value, bool float64, bool big_endian) {
  if (float64) {
    uint64_t bits;
    std::memcpy(&bits, &value, sizeof bits);
    PutScalar(at, bits, 8, big_endian);
  } else {
    const float narrow = static_cast<float>(value);
    uint32_t bits;
    std::memcpy(&bits, &narrow, sizeof bits);
    PutScalar(at, bits, 4, big_endian);
  }
}

struct Field {
  std::string name;
  uint32_t offset;
  uint8_t datatype;
};

std::vector<Field> CloudFields(const PointCloud2Options& options) {
  const uint8_t type = options.float64 ? kFloat64 : kFloat32;
  const uint32_t size = options.float64 ? 8 : 4;
  const uint32_t x = options.intensity ? 4 : 0;
  std::vector<Field> fields;
  if (options.intensity) fields.push_back({"intensity", 0, kFloat32});
  fields.push_back({"x", options.x_offset.value_or(x), options.x_datatype.value_or(type)});
  fields.push_back({"y", x + size, type});
  if (!options.omit_z) fields.push_back({"z", x + 2 * size, type});
  return fields;
}

// The point data: row-major, each point's intensity (its index), x, y, z,
// padding; each row then row_padding bytes.
std::vector<uint8_t> CloudData(const Points& all, const PointCloud2Options& options, uint32_t width,
                               uint32_t point_step, uint32_t row_step) {
  const uint32_t size = options.float64 ? 8 : 4;
  const uint32_t x = options.intensity ? 4 : 0;
  std::vector<uint8_t> data(size_t{row_step} * options.height, 0xEE);
  for (size_t i = 0; i < all.size(); ++i) {
    uint8_t* point = data.data() + (i / width) * row_step + (i % width) * point_step;
    if (options.intensity) PutCoordinate(point, static_cast<double>(i), false, options.big_endian);
    for (int axis = 0; axis < 3; ++axis) {
      PutCoordinate(point + x + axis * size, all[i][axis], options.float64, options.big_endian);
    }
  }
  return data;
}

void WritePose(MessageWriter& writer, const Transform& pose,
               const std::optional<Eigen::Vector4d>& quaternion_xyzw) {
  for (int i = 0; i < 3; ++i) writer.F64(pose(i, 3));
  Eigen::Vector4d q;
  if (quaternion_xyzw) {
    q = *quaternion_xyzw;
  } else {
    const Eigen::Quaterniond rotation(Eigen::Matrix3d(pose.topLeftCorner<3, 3>()));
    q = Eigen::Vector4d(rotation.x(), rotation.y(), rotation.z(), rotation.w());
  }
  for (int i = 0; i < 4; ++i) writer.F64(q[i]);
}

}  // namespace

std::vector<uint8_t> EncodePointCloud2(const Points& points, int64_t stamp_ns,
                                       const std::string& frame_id, MessageEncoding encoding,
                                       const PointCloud2Options& options) {
  Points all = points;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  all.insert(all.end(), options.nan_points, Point(nan, nan, nan));
  if (options.height == 0 || all.size() % options.height != 0) {
    throw std::invalid_argument("EncodePointCloud2: height does not divide the point count");
  }
  const uint32_t width = static_cast<uint32_t>(all.size() / options.height);
  const uint32_t point_step =
      (options.intensity ? 4 : 0) + 3 * (options.float64 ? 8 : 4) + options.point_padding;
  const uint32_t row_step = width * point_step + options.row_padding;

  MessageWriter writer(encoding, options.big_endian);
  writer.Header(stamp_ns, frame_id);
  writer.U32(options.height);
  writer.U32(options.width.value_or(width));
  const std::vector<Field> fields = CloudFields(options);
  writer.U32(static_cast<uint32_t>(fields.size()));
  for (const Field& field : fields) {
    writer.String(field.name);
    writer.U32(field.offset);
    writer.U8(field.datatype);
    writer.U32(1);
  }
  writer.U8(options.big_endian ? 1 : 0);
  writer.U32(options.point_step.value_or(point_step));
  writer.U32(options.row_step.value_or(row_step));
  writer.Bytes(CloudData(all, options, width, point_step, row_step));
  writer.U8(options.nan_points == 0 ? 1 : 0);
  return writer.Take();
}

std::vector<uint8_t> EncodeOdometry(const Transform& pose, int64_t stamp_ns,
                                    const std::string& frame_id, MessageEncoding encoding,
                                    const std::optional<Eigen::Vector4d>& quaternion_xyzw) {
  MessageWriter writer(encoding, false);
  writer.Header(stamp_ns, frame_id);
  writer.String("base_link");
  WritePose(writer, pose, quaternion_xyzw);
  for (int i = 0; i < 36 + 6 + 36; ++i) writer.F64(0.0);  // covariance, twist, covariance
  return writer.Take();
}

std::vector<uint8_t> EncodePoseStamped(const Transform& pose, int64_t stamp_ns,
                                       const std::string& frame_id, MessageEncoding encoding,
                                       const std::optional<Eigen::Vector4d>& quaternion_xyzw) {
  MessageWriter writer(encoding, false);
  writer.Header(stamp_ns, frame_id);
  WritePose(writer, pose, quaternion_xyzw);
  return writer.Take();
}

std::vector<uint8_t> EncodeTfMessage(const std::vector<FrameTransform>& transforms,
                                     int64_t stamp_ns, MessageEncoding encoding) {
  MessageWriter writer(encoding, false);
  writer.U32(static_cast<uint32_t>(transforms.size()));
  for (const FrameTransform& t : transforms) {
    writer.Header(stamp_ns, t.parent);
    writer.String(t.child);
    WritePose(writer, t.parent_child, std::nullopt);
  }
  return writer.Take();
}

}  // namespace boicp::test
