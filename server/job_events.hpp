#pragma once
// Where a running job reports state changes, finished pairs and progress.

#include "boicp/v1/map_builder.pb.h"

namespace boicp::server {

class JobEventSink {
 public:
  virtual ~JobEventSink() = default;
  /// Called from job and worker threads; must not block for long.
  virtual void Publish(const ::boicp::v1::JobEvent& event) = 0;
};

}  // namespace boicp::server
