#pragma once
// The standard grpc.health.v1.Health/Check, called through a generic stub:
// generating the health proto here too would register grpc.health.v1 twice
// in binaries that also link the tests' copy.

#include <chrono>
#include <memory>
#include <string>

#include <grpcpp/grpcpp.h>

namespace boicp::rpc {

/// grpc.health.v1.HealthCheckResponse.ServingStatus.
enum class ServingStatus { kUnknown = 0, kServing = 1, kNotServing = 2, kServiceUnknown = 3 };

/// "UNKNOWN", "SERVING", "NOT_SERVING", "SERVICE_UNKNOWN".
std::string ServingStatusName(ServingStatus status);

/// Checks `service` ("" = the whole server) with a deadline of `timeout`.
/// Throws RpcError (rpc "Check") when the call fails.
ServingStatus CheckHealth(const std::shared_ptr<grpc::Channel>& channel,
                          std::chrono::milliseconds timeout, const std::string& service = "");

}  // namespace boicp::rpc
