#pragma once
// Conversions between the boicp.v1 messages and core types, for the daemon
// and its clients alike, with the validation of what the other side sent
// (every failure is an InputError naming the field).

#include <cstdint>
#include <optional>
#include <string>

#include "boicp/io/point_cloud_io.hpp"
#include "boicp/mapping/batch_pairing.hpp"
#include "boicp/mapping/map_assembly.hpp"
#include "boicp/mapping/map_stage.hpp"
#include "boicp/util/types.hpp"
#include "boicp/v1/map_builder.pb.h"

namespace boicp::rpc {

namespace v1 = ::boicp::v1;

/// A rigid transform: 16 finite numbers, last row 0 0 0 1, orthonormal
/// rotation with determinant +1 (tolerance 1e-3). Throws InputError naming `field`.
Transform TransformFromProto(const v1::Transform& proto, const std::string& field);
void TransformToProto(const Transform& T, v1::Transform* proto);

/// Throws InputError naming `field` unless all three are finite.
Point PointFromProto(const v1::Vector3& proto, const std::string& field);
v1::Vector3 PointToProto(const Point& point);

/// Throws InputError for SCAN_FORMAT_UNSPECIFIED or a value this daemon does not know.
CloudFormat FormatFromProto(int format);
/// SCAN_FORMAT_UNSPECIFIED for kAuto.
v1::ScanFormat ScanFormatOf(CloudFormat format);

/// "trajectory-driveK", the stem of drive K's trajectory files (K >= 1).
std::string DriveTrajectoryStem(uint32_t drive);

/// The file a job's export is stored and saved as: "map.bt", "map.ot",
/// "trajectory.tum", "trajectory.kitti" or "map.ply"; nullopt for a format
/// value that is not one of the five. With `drive` K >= 1, a trajectory
/// format's file of drive K alone, "trajectory-driveK.tum" or ".kitti"
/// (nullopt for the others).
std::optional<std::string> ExportFileName(int format, uint32_t drive = 0);

/// Format and depth options to load a stored scan with. Throws InputError
/// when a depth image lacks intrinsics or scale.
LoadOptions LoadOptionsFromMetadata(const v1::ScanMetadata& metadata);

/// The upload metadata of a scan: format (explicit, else from the extension),
/// depth camera, sensor origin, prior pose T_world_scan and timestamp. Throws
/// InputError naming the file when a depth image lacks intrinsics or scale.
v1::ScanMetadata ScanMetadataOf(const ScanSource& scan);

/// A scan's context for SubmitBatchRequest.scan_context: the sensor origin,
/// prior pose and timestamp ScanMetadataOf sends, from the same fields.
v1::ScanContext ScanContextOf(const ScanSource& scan);

/// Every check UploadScan makes on its metadata message before any byte
/// arrives: format and depth camera, sensor origin, prior pose, and the
/// optional sha256 (64 lowercase hex digits). Throws InputError naming the field.
void ValidateScanMetadata(const v1::ScanMetadata& metadata);

/// A batch's pairing as asked (MODE_UNSPECIFIED is consecutive, MODE_OVERLAP
/// overlap). Throws InputError for a mode this daemon does not know.
PairingRequest PairingFromProto(const v1::PairingPolicy& proto);
v1::PairingPolicy PairingToProto(const PairingRequest& pairing);

/// The rung whose answer a pair kept (RungName's word). Results stored
/// before it was recorded carry none: every answer then was a full search.
std::string AnsweredBy(const v1::PairResult& pair);

/// True for SUCCEEDED, FAILED and CANCELLED.
bool IsTerminal(v1::JobState state);
/// "queued", "running", "succeeded", "failed", "cancelled" ("unspecified" otherwise).
std::string JobStateName(v1::JobState state);

/// Sets the job's stage_code and, from it, its stage name ("fusing").
void SetJobStage(v1::Job& job, v1::JobStage stage);
/// The stage a map stage is in the API.
v1::JobStage JobStageOf(MapStage stage);
/// The stage named `name` ("queued", "fusing", ...); JOB_STAGE_UNSPECIFIED
/// for another name. Jobs stored before stage_code existed get it from here.
v1::JobStage JobStageFromName(const std::string& name);

/// Seconds since the Unix epoch, for the *_at fields.
double NowSeconds();

}  // namespace boicp::rpc
