#pragma once
// A job as the runner needs it, built from the stored request (with the
// batch's scan context, if it sent one) and the snapshot of its scans'
// metadata. The same function validates a batch at submission and rebuilds
// it when a restarted daemon resumes the job, so both see the same
// configuration.

#include <string>
#include <vector>

#include "boicp/mapping/batch_pair.hpp"
#include "boicp/mapping/map_assembly.hpp"
#include "boicp/mapping/map_batch.hpp"
#include "boicp/registration/config.hpp"
#include "boicp/v1/map_builder.pb.h"
#include "data_dir.hpp"

namespace boicp::server {

namespace v1 = ::boicp::v1;

struct JobSpec {
  std::string job_id;
  std::vector<std::string> scan_ids;  // batch.scans[i] is the stored scan scan_ids[i]
  MapBatch batch;                     // batch.config.seed is the job seed
};

/// The settings a job runs with, for its record: `config` and `map` as
/// resolved, the names of the fields chosen from the scans and the far
/// returns set aside while choosing them.
v1::ChosenSettings ChosenSettingsToProto(const BoIcpConfig& config, const MapBuildSettings& map,
                                         const BatchSettingsChoice& choice);

/// Validates everything about a batch except that its scans exist (the
/// caller looked them up to get `scans`, the job's snapshot of their stored
/// records). Each scan decodes as its record says; its context (sensor
/// origin, prior pose, timestamp) is the request's scan_context entry when
/// the batch sends them, else the record's. Throws InputError naming the
/// field (e.g. "scan_context[3].prior_pose").
JobSpec BuildJobSpec(const std::string& job_id, const v1::SubmitBatchRequest& request,
                     const std::vector<v1::ScanMetadata>& scans, const DataDir& data_dir,
                     int registration_threads);

}  // namespace boicp::server
