#include "service_error.hpp"

#include <spdlog/spdlog.h>

#include "boicp/util/types.hpp"
#include "storage_errors.hpp"

namespace boicp::server {

grpc::Status StatusFromCurrentException(const char* rpc) {
  try {
    throw;
  } catch (const ServiceError& e) {
    return grpc::Status(e.code(), e.what());
  } catch (const InputError& e) {
    return grpc::Status(grpc::StatusCode::INVALID_ARGUMENT, e.what());
  } catch (const LimitExceeded& e) {
    return grpc::Status(grpc::StatusCode::RESOURCE_EXHAUSTED, e.what());
  } catch (const StorageError& e) {
    spdlog::warn("{}: refused: {}", rpc, e.what());
    return grpc::Status(grpc::StatusCode::FAILED_PRECONDITION, e.what());
  } catch (const CorruptScanError& e) {
    return grpc::Status(grpc::StatusCode::DATA_LOSS, e.what());
  } catch (const std::exception& e) {
    spdlog::error("{}: internal error: {}", rpc, e.what());
    return grpc::Status(grpc::StatusCode::INTERNAL, std::string("internal error: ") + e.what());
  } catch (...) {
    spdlog::error("{}: internal error of unknown type", rpc);
    return grpc::Status(grpc::StatusCode::INTERNAL, "internal error");
  }
}

}  // namespace boicp::server
