#include "boicp/mapping/pair_scale.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace boicp {

namespace {

const std::vector<std::string> kLengthFields = {"voxel", "refine_voxel", "objective_truncation",
                                                "translation_bounds"};

bool Listed(const std::vector<std::string>& names, const std::string& name) {
  return std::find(names.begin(), names.end(), name) != names.end();
}

double RangeOf(const BatchScale& scale, size_t index) {
  return index < scale.scan_ranges.size() ? scale.scan_ranges[index] : 0.0;
}

// log2 of range / reference, or 0 when either is unknown.
double ScaleOctaves(const BatchScale& scale, double range) {
  if (!(scale.reference_range > 0.0) || !(range > 0.0)) return 0.0;
  return std::log2(range / scale.reference_range);
}

bool SameScale(double octaves) { return std::abs(octaves) <= std::log2(kSameScaleFactor); }

}  // namespace

double MedianRange(const RangeProfile& profile) {
  uint64_t total = 0;
  for (const uint32_t count : profile.counts) total += count;
  if (total == 0) return 0.0;
  uint64_t below = 0;
  for (size_t bin = 0; bin < profile.counts.size(); ++bin) {
    below += profile.counts[bin];
    if (2 * below >= total) return RangeBinUpperEdge(static_cast<int>(bin));
  }
  return RangeBinUpperEdge(static_cast<int>(profile.counts.size()) - 1);
}

BatchScale MeasureBatchScale(const std::vector<RangeProfile>& profiles,
                             const std::vector<size_t>& measured,
                             const std::vector<std::string>& auto_fields) {
  BatchScale scale;
  for (const RangeProfile& profile : profiles) scale.scan_ranges.push_back(MedianRange(profile));
  if (!Listed(auto_fields, "voxel")) return scale;
  std::vector<double> ranges;
  for (const size_t index : measured) {
    const double range = RangeOf(scale, index);
    if (range > 0.0) ranges.push_back(range);
  }
  // A measured scan without a profile leaves the reference unknown.
  if (ranges.empty() || ranges.size() < measured.size()) return scale;
  std::nth_element(ranges.begin(), ranges.begin() + ranges.size() / 2, ranges.end());
  scale.reference_range = ranges[ranges.size() / 2];
  for (const std::string& field : kLengthFields) {
    if (Listed(auto_fields, field)) scale.fields.push_back(field);
  }
  return scale;
}

int PairScaleStep(const BatchScale& scale, const PairIndex& pair) {
  const double source = RangeOf(scale, static_cast<size_t>(pair.source));
  const double target = RangeOf(scale, static_cast<size_t>(pair.target));
  if (!(source > 0.0) || !(target > 0.0)) return 0;
  const double octaves = ScaleOctaves(scale, 0.5 * (source + target));
  return SameScale(octaves) ? 0 : static_cast<int>(std::lround(octaves));
}

bool ScanAtAnotherScale(const BatchScale& scale, size_t index) {
  return !SameScale(ScaleOctaves(scale, RangeOf(scale, index)));
}

std::string DescribeScansAtAnotherScale(const BatchScale& scale) {
  size_t count = 0;
  for (size_t i = 0; i < scale.scan_ranges.size(); ++i) count += ScanAtAnotherScale(scale, i);
  if (count == 0) return "";
  char text[256];
  std::snprintf(text, sizeof text,
                "%zu of %zu scans reach over %g times nearer or farther than the measured ones "
                "(median range %.3g m); their pairs search at settings scaled to fit",
                count, scale.scan_ranges.size(), kSameScaleFactor, scale.reference_range);
  return text;
}

BoIcpConfig ScaledConfig(const BoIcpConfig& config, const BatchScale& scale, int step) {
  if (step == 0) return config;
  const double factor = std::exp2(step);
  BoIcpConfig scaled = config;
  for (const std::string& field : scale.fields) {
    if (field == "voxel") {
      scaled.voxel *= factor;
      scaled.retry_voxel *= factor;
    }
    if (field == "refine_voxel") scaled.refine_voxel *= factor;
    if (field == "objective_truncation") scaled.objective_truncation *= factor;
    if (field == "translation_bounds") scaled.translation_bounds *= factor;
  }
  return scaled;
}

}  // namespace boicp
