#include "boicp/rpc/proto_convert.hpp"

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <iterator>
#include <limits>
#include <utility>

#include <Eigen/Dense>

#include "boicp/registration/bo_icp.hpp"
#include "boicp/rpc/sha256.hpp"
#include "boicp/util/text.hpp"

namespace boicp::rpc {
namespace {

// Every scan format with its API value; both directions read this table.
constexpr std::pair<CloudFormat, v1::ScanFormat> kScanFormats[] = {
    {CloudFormat::kKittiBin, v1::SCAN_FORMAT_KITTI_BIN},
    {CloudFormat::kPcd, v1::SCAN_FORMAT_PCD},
    {CloudFormat::kPly, v1::SCAN_FORMAT_PLY},
    {CloudFormat::kXyz, v1::SCAN_FORMAT_XYZ},
    {CloudFormat::kDepthPng, v1::SCAN_FORMAT_DEPTH_PNG},
};

// Every pairing mode with its API value (MODE_UNSPECIFIED reads as consecutive).
constexpr std::pair<PairingMode, v1::PairingPolicy::Mode> kPairingModes[] = {
    {PairingMode::kConsecutive, v1::PairingPolicy::MODE_CONSECUTIVE},
    {PairingMode::kOverlap, v1::PairingPolicy::MODE_OVERLAP},
    {PairingMode::kExplicit, v1::PairingPolicy::MODE_EXPLICIT},
};

}  // namespace

Transform TransformFromProto(const v1::Transform& proto, const std::string& field) {
  if (proto.m_size() != 16) {
    throw InputError(field + ": a transform has 16 numbers (row-major 4x4), got " +
                     std::to_string(proto.m_size()));
  }
  Transform T;
  for (int i = 0; i < 16; ++i) {
    if (!std::isfinite(proto.m(i))) throw InputError(field + ": non-finite entry");
    T(i / 4, i % 4) = proto.m(i);
  }
  constexpr double kTolerance = 1e-3;
  if (std::abs(T(3, 0)) > kTolerance || std::abs(T(3, 1)) > kTolerance ||
      std::abs(T(3, 2)) > kTolerance || std::abs(T(3, 3) - 1.0) > kTolerance) {
    throw InputError(field + ": the last row must be 0 0 0 1");
  }
  const Eigen::Matrix3d R = T.topLeftCorner<3, 3>();
  if ((R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() > kTolerance ||
      R.determinant() < 0.0) {
    throw InputError(field + ": the rotation part is not a rotation (orthonormal, det +1)");
  }
  T.row(3) << 0.0, 0.0, 0.0, 1.0;
  return T;
}

void TransformToProto(const Transform& T, v1::Transform* proto) {
  proto->clear_m();
  for (int i = 0; i < 16; ++i) proto->add_m(T(i / 4, i % 4));
}

v1::Vector3 PointToProto(const Point& point) {
  v1::Vector3 out;
  out.set_x(point.x());
  out.set_y(point.y());
  out.set_z(point.z());
  return out;
}

Point PointFromProto(const v1::Vector3& proto, const std::string& field) {
  const Point p(proto.x(), proto.y(), proto.z());
  if (!p.allFinite()) throw InputError(field + ": non-finite value");
  return p;
}

v1::ScanFormat ScanFormatOf(CloudFormat format) {
  for (const auto& [cloud, proto] : kScanFormats) {
    if (cloud == format) return proto;
  }
  return v1::SCAN_FORMAT_UNSPECIFIED;
}

CloudFormat FormatFromProto(int format) {
  if (format == v1::SCAN_FORMAT_UNSPECIFIED) {
    throw InputError("metadata.format is required (kitti_bin, pcd, ply, xyz or depth_png)");
  }
  for (const auto& [cloud, proto] : kScanFormats) {
    if (proto == format) return cloud;
  }
  throw InputError("metadata.format: unknown scan format " + std::to_string(format));
}

LoadOptions LoadOptionsFromMetadata(const v1::ScanMetadata& metadata) {
  LoadOptions options;
  options.format = FormatFromProto(metadata.format());
  if (options.format != CloudFormat::kDepthPng) return options;
  if (!metadata.has_depth()) {
    throw InputError("metadata.depth: a depth image needs intrinsics and depth_scale");
  }
  const v1::DepthCamera& d = metadata.depth();
  if (!(d.fx() > 0.0 && d.fy() > 0.0) || !std::isfinite(d.fx()) || !std::isfinite(d.fy()) ||
      !std::isfinite(d.cx()) || !std::isfinite(d.cy())) {
    throw InputError("metadata.depth: fx and fy must be positive, cx and cy finite");
  }
  if (!(d.depth_scale() > 0.0) || !std::isfinite(d.depth_scale())) {
    throw InputError("metadata.depth.depth_scale must be positive (TUM 5000, 7-Scenes 1000)");
  }
  options.depth.intrinsics = Intrinsics{d.fx(), d.fy(), d.cx(), d.cy()};
  options.depth.depth_scale = d.depth_scale();
  if (d.invalid_values_size() > 0) {
    options.depth.invalid_values.clear();
    for (uint32_t v : d.invalid_values()) {
      if (v > 65535) throw InputError("metadata.depth.invalid_values must be in 0..65535");
      options.depth.invalid_values.push_back(static_cast<uint16_t>(v));
    }
  }
  return options;
}

v1::ScanMetadata ScanMetadataOf(const ScanSource& scan) {
  CloudFormat format =
      scan.load.format == CloudFormat::kAuto ? DetectCloudFormat(scan.path) : scan.load.format;
  // A scan inside a bag travels as the binary PCD of its points (MapBuilderClient::UploadScan).
  if (format == CloudFormat::kRosMessage) format = CloudFormat::kPcd;
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
  const v1::ScanContext context = ScanContextOf(scan);
  *metadata.mutable_sensor_origin() = context.sensor_origin();
  if (context.has_prior_pose()) *metadata.mutable_prior_pose() = context.prior_pose();
  if (context.has_timestamp()) metadata.set_timestamp(context.timestamp());
  return metadata;
}

v1::ScanContext ScanContextOf(const ScanSource& scan) {
  v1::ScanContext context;
  *context.mutable_sensor_origin() = PointToProto(scan.sensor_origin);
  if (scan.prior_pose) TransformToProto(*scan.prior_pose, context.mutable_prior_pose());
  if (scan.timestamp) context.set_timestamp(*scan.timestamp);
  return context;
}

void ValidateScanMetadata(const v1::ScanMetadata& metadata) {
  LoadOptionsFromMetadata(metadata);
  if (metadata.has_sensor_origin()) {
    PointFromProto(metadata.sensor_origin(), "metadata.sensor_origin");
  }
  if (metadata.has_prior_pose()) TransformFromProto(metadata.prior_pose(), "metadata.prior_pose");
  if (!metadata.sha256().empty() && !IsSha256Hex(metadata.sha256())) {
    throw InputError("metadata.sha256 must be 64 lowercase hex digits");
  }
}

PairingRequest PairingFromProto(const v1::PairingPolicy& proto) {
  PairingRequest pairing;
  const auto known = std::find_if(std::begin(kPairingModes), std::end(kPairingModes),
                                  [&](const auto& entry) { return entry.second == proto.mode(); });
  if (known != std::end(kPairingModes)) {
    pairing.mode = known->first;
  } else if (proto.mode() != v1::PairingPolicy::MODE_UNSPECIFIED) {
    throw InputError("pairing.mode: unknown mode " + std::to_string(proto.mode()));
  }
  pairing.overlap_threshold = proto.overlap_threshold();
  for (const v1::Pair& p : proto.pairs()) {
    pairing.pairs.push_back({static_cast<int>(p.source()), static_cast<int>(p.target())});
  }
  for (const uint32_t start : proto.drive_starts()) {
    if (start > static_cast<uint32_t>(std::numeric_limits<int>::max())) {
      throw InputError("pairing.drive_starts: " + std::to_string(start) + " is no scan index");
    }
    pairing.drive_starts.push_back(static_cast<int>(start));
  }
  return pairing;
}

v1::PairingPolicy PairingToProto(const PairingRequest& pairing) {
  v1::PairingPolicy proto;
  for (const auto& [mode, value] : kPairingModes) {
    if (mode == pairing.mode) proto.set_mode(value);
  }
  proto.set_overlap_threshold(pairing.overlap_threshold);
  for (const PairIndex& p : pairing.pairs) {
    v1::Pair* pair = proto.add_pairs();
    pair->set_source(static_cast<uint32_t>(p.source));
    pair->set_target(static_cast<uint32_t>(p.target));
  }
  for (const int start : pairing.drive_starts) proto.add_drive_starts(static_cast<uint32_t>(start));
  return proto;
}

std::string AnsweredBy(const v1::PairResult& pair) {
  return pair.answered_by().empty() ? RungName(Rung::kFullSearch) : pair.answered_by();
}

bool IsTerminal(v1::JobState state) {
  return state == v1::JOB_STATE_SUCCEEDED || state == v1::JOB_STATE_FAILED ||
         state == v1::JOB_STATE_CANCELLED;
}

namespace {
constexpr const char kStagePrefix[] = "JOB_STAGE_";
}  // namespace

void SetJobStage(v1::Job& job, v1::JobStage stage) {
  job.set_stage_code(stage);
  job.set_stage(LowerCase(v1::JobStage_Name(stage).substr(sizeof(kStagePrefix) - 1)));
}

v1::JobStage JobStageOf(MapStage stage) { return JobStageFromName(MapStageName(stage)); }

v1::JobStage JobStageFromName(const std::string& name) {
  std::string upper = kStagePrefix + name;
  std::transform(upper.begin(), upper.end(), upper.begin(),
                 [](unsigned char c) { return static_cast<char>(std::toupper(c)); });
  v1::JobStage stage = v1::JOB_STAGE_UNSPECIFIED;
  return v1::JobStage_Parse(upper, &stage) ? stage : v1::JOB_STAGE_UNSPECIFIED;
}

std::string JobStateName(v1::JobState state) {
  switch (state) {
    case v1::JOB_STATE_QUEUED:
      return "queued";
    case v1::JOB_STATE_RUNNING:
      return "running";
    case v1::JOB_STATE_SUCCEEDED:
      return "succeeded";
    case v1::JOB_STATE_FAILED:
      return "failed";
    case v1::JOB_STATE_CANCELLED:
      return "cancelled";
    default:
      return "unspecified";
  }
}

double NowSeconds() {
  return std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
}

std::string DriveTrajectoryStem(uint32_t drive) {
  return "trajectory-drive" + std::to_string(drive);
}

std::optional<std::string> ExportFileName(int format, uint32_t drive) {
  if (drive > 0) {
    if (format == v1::EXPORT_FORMAT_TRAJECTORY_TUM) return DriveTrajectoryStem(drive) + ".tum";
    if (format == v1::EXPORT_FORMAT_TRAJECTORY_KITTI) return DriveTrajectoryStem(drive) + ".kitti";
    return std::nullopt;
  }
  switch (format) {
    case v1::EXPORT_FORMAT_OCTOMAP_BT:
      return "map.bt";
    case v1::EXPORT_FORMAT_OCTOMAP_OT:
      return "map.ot";
    case v1::EXPORT_FORMAT_TRAJECTORY_TUM:
      return "trajectory.tum";
    case v1::EXPORT_FORMAT_TRAJECTORY_KITTI:
      return "trajectory.kitti";
    case v1::EXPORT_FORMAT_POINT_CLOUD_PLY:
      return "map.ply";
    default:
      return std::nullopt;
  }
}

}  // namespace boicp::rpc
