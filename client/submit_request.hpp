#pragma once
// The batch request `boicp submit` sends for a run, built once for the
// command and for the Python client.

#include <string>

#include "boicp/v1/map_builder.pb.h"
#include "local_pipeline.hpp"

namespace boicp::cli {

/// The request for `run` (PrepareRun): its pairing, and only the settings
/// the user set, so the daemon applies the same preset defaults as this
/// client; each scan's context (sensor origin, prior, timestamp) in scan
/// order; `label`, or the folder's path when empty. No scan ids: the
/// uploads give them, in the same order.
v1::SubmitBatchRequest BuildSubmitRequest(const LocalRun& run, const std::string& label);

}  // namespace boicp::cli
