#include "service_error.hpp"

#include <spdlog/spdlog.h>

#include "boicp/util/types.hpp"
#include "storage_errors.hpp"

namespace boicp::server {
namespace {

bool StartsAPath(const std::string& text, size_t i) {
  return text[i] == '/' && (i == 0 || std::string(" (\"'=").find(text[i - 1]) != std::string::npos);
}

// A path ends at white space, a closing bracket or quote, or a colon that
// ends a clause ("PATH: cannot open").
bool EndsAPath(const std::string& text, size_t i) {
  const char c = text[i];
  if (std::string(" \t\n),;\"'").find(c) != std::string::npos) return true;
  return c == ':' && (i + 1 == text.size() || text[i + 1] == ' ');
}

grpc::Status Reply(grpc::StatusCode code, const std::string& message) {
  return grpc::Status(code, WithoutServerPaths(message));
}

}  // namespace

std::string WithoutServerPaths(const std::string& text) {
  std::string out;
  for (size_t i = 0; i < text.size();) {
    if (!StartsAPath(text, i)) {
      out += text[i++];
      continue;
    }
    size_t end = i;
    while (end < text.size() && !EndsAPath(text, end)) ++end;
    const std::string path = text.substr(i, end - i);
    out += ".../" + path.substr(path.find_last_of('/') + 1);
    i = end;
  }
  return out;
}

grpc::Status StatusFromCurrentException(const char* rpc) {
  try {
    throw;
  } catch (const ServiceError& e) {
    return Reply(e.code(), e.what());
  } catch (const InputError& e) {
    return Reply(grpc::StatusCode::INVALID_ARGUMENT, e.what());
  } catch (const LimitExceeded& e) {
    return Reply(grpc::StatusCode::RESOURCE_EXHAUSTED, e.what());
  } catch (const StorageError& e) {
    spdlog::warn("{}: refused: {}", rpc, e.what());
    return Reply(grpc::StatusCode::FAILED_PRECONDITION, e.reply());
  } catch (const CorruptScanError& e) {
    return Reply(grpc::StatusCode::DATA_LOSS, e.what());
  } catch (const std::exception& e) {
    spdlog::error("{}: internal error: {}", rpc, e.what());
    return Reply(grpc::StatusCode::INTERNAL, std::string("internal error: ") + e.what());
  } catch (...) {
    spdlog::error("{}: internal error of unknown type", rpc);
    return grpc::Status(grpc::StatusCode::INTERNAL, "internal error");
  }
}

}  // namespace boicp::server
