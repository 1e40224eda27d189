#include "job_limits.hpp"

#include <cmath>
#include <sstream>
#include <string>

#include "boicp/util/types.hpp"

namespace boicp::server {
namespace {

namespace v1 = ::boicp::v1;

template <typename Value, typename Limit>
void RequireAtMost(const std::string& field, Value value, Limit limit) {
  if (!(value <= limit)) {
    std::ostringstream message;
    message << field << ": " << value << " is over the limit of " << limit;
    throw InputError(message.str());
  }
}

template <typename Value, typename Limit>
void RequireAtLeast(const std::string& field, Value value, Limit limit) {
  if (!(value >= limit)) {
    std::ostringstream message;
    message << field << ": " << value << " is under the limit of " << limit;
    throw InputError(message.str());
  }
}

void RequireHalfWidthsAtMost(const std::string& field, const v1::Vector3& v, double limit) {
  RequireAtMost(field + ".x", v.x(), limit);
  RequireAtMost(field + ".y", v.y(), limit);
  RequireAtMost(field + ".z", v.z(), limit);
}

void RequireSearchWithinLimits(const v1::RegistrationConfig& c, const JobLimits& limits) {
  if (c.has_random_samples()) {
    RequireAtMost("config.random_samples", c.random_samples(), limits.max_random_samples);
  }
  if (c.has_iterations()) RequireAtMost("config.iterations", c.iterations(), limits.max_iterations);
  if (c.has_evaluation_points()) {
    RequireAtMost("config.evaluation_points", c.evaluation_points(), limits.max_evaluation_points);
  }
  if (c.has_rotation_bounds()) {
    RequireHalfWidthsAtMost("config.rotation_bounds", c.rotation_bounds(), M_PI);
  }
  if (c.has_translation_bounds()) {
    RequireHalfWidthsAtMost("config.translation_bounds", c.translation_bounds(),
                            limits.max_translation_bounds_m);
  }
  if (c.has_min_range()) RequireAtMost("config.min_range", c.min_range(), limits.max_range_m);
  if (c.has_max_range()) RequireAtMost("config.max_range", c.max_range(), limits.max_range_m);
}

// A ray visits range / resolution cells; a map of fine leaves needs a short ray.
void RequireMapWithinLimits(const v1::MapSettings& m, const JobLimits& limits) {
  if (m.resolution() != 0.0) {
    RequireAtLeast("map.resolution", m.resolution(), limits.min_map_resolution_m);
  }
  RequireAtMost("map.max_range", m.max_range(), limits.max_range_m);
  const double resolution = m.resolution() != 0.0 ? m.resolution() : 0.2;
  const double ray = m.max_range() != 0.0 ? m.max_range() : limits.unlimited_ray_m;
  if (ray / resolution > limits.max_cells_per_ray) {
    std::ostringstream message;
    message << "map.max_range: rays of " << ray << " m"
            << (m.max_range() == 0.0 ? " (0 = no limit)" : "") << " over " << resolution
            << " m leaves cross " << ray / resolution << " cells, over the limit of "
            << limits.max_cells_per_ray << "; shorten map.max_range or coarsen map.resolution";
    throw InputError(message.str());
  }
  if (m.cloud_voxel() != 0.0) {
    RequireAtLeast("map.cloud_voxel", m.cloud_voxel(), limits.min_cloud_voxel_m);
  }
}

}  // namespace

void RequireWithinJobLimits(const v1::SubmitBatchRequest& request, const JobLimits& limits) {
  RequireSearchWithinLimits(request.config(), limits);
  RequireMapWithinLimits(request.map(), limits);
  RequireAtMost("pairing.pairs", request.pairing().pairs_size(), limits.max_listed_pairs);
  if (request.label().size() > limits.max_label_bytes) {
    throw InputError("label: " + std::to_string(request.label().size()) +
                     " bytes is over the limit of " + std::to_string(limits.max_label_bytes));
  }
}

}  // namespace boicp::server
