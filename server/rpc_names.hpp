#pragma once
// The rpc library's proto conversions and content hash under the daemon's
// namespace, so that the daemon's code names them as its own.

#include "boicp/rpc/proto_convert.hpp"
#include "boicp/rpc/sha256.hpp"

namespace boicp::server {

using rpc::FormatFromProto;
using rpc::IsSha256Hex;
using rpc::IsTerminal;
using rpc::JobStateName;
using rpc::LoadOptionsFromMetadata;
using rpc::NowSeconds;
using rpc::PointFromProto;
using rpc::PointToProto;
using rpc::Sha256;
using rpc::TransformFromProto;
using rpc::TransformToProto;
using rpc::ValidateScanMetadata;

}  // namespace boicp::server
