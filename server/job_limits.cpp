#include "job_limits.hpp"

#include <cmath>
#include <sstream>
#include <string>
#include <type_traits>

#include "boicp/mapping/occupancy_map.hpp"
#include "boicp/rpc/settings_proto.hpp"
#include "boicp/settings/setting_schema.hpp"
#include "boicp/util/types.hpp"

namespace boicp::server {
namespace {

namespace v1 = ::boicp::v1;
using settings::RequestLimits;
using settings::SettingField;

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

// A count's limit is shown as a count ("1000000", not "1e+06").
template <typename T>
auto LimitAs(double limit) {
  if constexpr (std::is_integral_v<T>) {
    return static_cast<T>(limit);
  } else {
    return limit;
  }
}

template <typename T>
void RequireWithin(const std::string& field, T value, const RequestLimits& limits) {
  if (std::isfinite(limits.lower)) RequireAtLeast(field, value, LimitAs<T>(limits.lower));
  if (std::isfinite(limits.upper)) RequireAtMost(field, value, LimitAs<T>(limits.upper));
}

void RequireWithin(const std::string& field, const Eigen::Vector3d& value,
                   const RequestLimits& limits) {
  RequireWithin(field + ".x", value.x(), limits);
  RequireWithin(field + ".y", value.y(), limits);
  RequireWithin(field + ".z", value.z(), limits);
}

// Every given setting within the schema's limits for it.
void RequireSettingsWithinLimits(const v1::SubmitBatchRequest& request) {
  const settings::RequestedSettings given = rpc::SettingsFromProto(request.config(), request.map());
  for (const SettingField& field : settings::SettingSchema()) {
    if (field.message == settings::ProtoMessage::kNone) continue;
    std::visit(
        [&](const auto& binding) {
          if constexpr (!settings::kIsPlainBinding<std::decay_t<decltype(binding)>>) {
            const auto& value = given.*binding.requested;
            if (value) RequireWithin(rpc::ProtoFieldPath(field), *value, field.limits);
          }
        },
        field.binding);
  }
}

// A ray visits range / resolution cells; a map of fine leaves needs a short
// ray. A ray of no limit (0) is taken to reach as far as a given one may.
void RequireRaysWithinLimits(const v1::MapSettings& m, const JobLimits& limits) {
  const double longest_ray = settings::FindSetting("max_range")->limits.upper;
  const double resolution = m.resolution() != 0.0 ? m.resolution() : OccupancySettings().resolution;
  const double ray = m.max_range() != 0.0 ? m.max_range() : longest_ray;
  if (ray / resolution > limits.max_cells_per_ray) {
    std::ostringstream message;
    message << "map.max_range: rays of " << ray << " m"
            << (m.max_range() == 0.0 ? " (0 = no limit)" : "") << " over " << resolution
            << " m leaves cross " << ray / resolution << " cells, over the limit of "
            << limits.max_cells_per_ray << "; shorten map.max_range or coarsen map.resolution";
    throw InputError(message.str());
  }
}

}  // namespace

void RequireWithinJobLimits(const v1::SubmitBatchRequest& request, const JobLimits& limits) {
  RequireSettingsWithinLimits(request);
  RequireRaysWithinLimits(request.map(), limits);
  RequireAtMost("pairing.pairs", request.pairing().pairs_size(), limits.max_listed_pairs);
  if (request.label().size() > limits.max_label_bytes) {
    throw InputError("label: " + std::to_string(request.label().size()) +
                     " bytes is over the limit of " + std::to_string(limits.max_label_bytes));
  }
}

}  // namespace boicp::server
