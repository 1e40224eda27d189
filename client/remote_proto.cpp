#include "remote_proto.hpp"

#include <algorithm>
#include <cctype>

namespace boicp::cli {
namespace {

v1::ScanFormat ScanFormatOf(CloudFormat format) {
  switch (format) {
    case CloudFormat::kKittiBin:
      return v1::SCAN_FORMAT_KITTI_BIN;
    case CloudFormat::kPcd:
      return v1::SCAN_FORMAT_PCD;
    case CloudFormat::kPly:
      return v1::SCAN_FORMAT_PLY;
    case CloudFormat::kXyz:
      return v1::SCAN_FORMAT_XYZ;
    case CloudFormat::kDepthPng:
      return v1::SCAN_FORMAT_DEPTH_PNG;
    case CloudFormat::kAuto:
      break;
  }
  return v1::SCAN_FORMAT_UNSPECIFIED;
}

}  // namespace

void TransformToProto(const Transform& T, v1::Transform* proto) {
  proto->clear_m();
  for (int row = 0; row < 4; ++row) {
    for (int col = 0; col < 4; ++col) proto->add_m(T(row, col));
  }
}

Transform TransformFromProto(const v1::Transform& proto, const std::string& field) {
  if (proto.m_size() != 16) {
    throw InputError(field + ": expected 16 numbers, got " + std::to_string(proto.m_size()));
  }
  Transform T;
  for (int row = 0; row < 4; ++row) {
    for (int col = 0; col < 4; ++col) T(row, col) = proto.m(4 * row + col);
  }
  return T;
}

v1::ScanMetadata ScanMetadataOf(const ScanSource& scan) {
  const CloudFormat format =
      scan.load.format == CloudFormat::kAuto ? DetectCloudFormat(scan.path) : scan.load.format;
  v1::ScanMetadata metadata;
  metadata.set_format(ScanFormatOf(format));
  if (format == CloudFormat::kDepthPng) {
    const DepthOptions& depth = scan.load.depth;
    if (!depth.intrinsics || !(depth.depth_scale > 0.0)) {
      throw InputError(scan.path + ": a depth image needs intrinsics and a depth scale > 0");
    }
    v1::DepthCamera& camera = *metadata.mutable_depth();
    camera.set_fx(depth.intrinsics->fx);
    camera.set_fy(depth.intrinsics->fy);
    camera.set_cx(depth.intrinsics->cx);
    camera.set_cy(depth.intrinsics->cy);
    camera.set_depth_scale(depth.depth_scale);
    for (uint16_t value : depth.invalid_values) camera.add_invalid_values(value);
  }
  metadata.mutable_sensor_origin()->set_x(scan.sensor_origin.x());
  metadata.mutable_sensor_origin()->set_y(scan.sensor_origin.y());
  metadata.mutable_sensor_origin()->set_z(scan.sensor_origin.z());
  if (scan.prior_pose) TransformToProto(*scan.prior_pose, metadata.mutable_prior_pose());
  if (scan.timestamp) metadata.set_timestamp(*scan.timestamp);
  return metadata;
}

std::string JobStateName(v1::JobState state) {
  std::string name = v1::JobState_Name(state);  // e.g. "JOB_STATE_SUCCEEDED"
  const std::string prefix = "JOB_STATE_";
  if (name.rfind(prefix, 0) == 0) name = name.substr(prefix.size());
  std::transform(name.begin(), name.end(), name.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return name;
}

bool IsFinal(v1::JobState state) {
  return state == v1::JOB_STATE_SUCCEEDED || state == v1::JOB_STATE_FAILED ||
         state == v1::JOB_STATE_CANCELLED;
}

}  // namespace boicp::cli
