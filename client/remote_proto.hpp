#pragma once
// Client-side conversions between core types and boicp.v1 messages.

#include <string>

#include "boicp/mapping/map_assembly.hpp"
#include "boicp/util/types.hpp"
#include "boicp/v1/map_builder.pb.h"

namespace boicp::cli {

namespace v1 = ::boicp::v1;

/// Row-major 16 numbers.
void TransformToProto(const Transform& T, v1::Transform* proto);
/// Throws InputError naming `field` unless the message holds 16 numbers.
Transform TransformFromProto(const v1::Transform& proto, const std::string& field);

/// The upload metadata of a scan: format (explicit, else from the extension),
/// depth camera, sensor origin, prior pose T_world_scan and timestamp. Throws
/// InputError naming the file when a depth image lacks intrinsics or scale.
v1::ScanMetadata ScanMetadataOf(const ScanSource& scan);

/// "queued", "running", "succeeded", "failed", "cancelled" ("unspecified").
std::string JobStateName(v1::JobState state);

/// True for SUCCEEDED, FAILED and CANCELLED.
bool IsFinal(v1::JobState state);

}  // namespace boicp::cli
