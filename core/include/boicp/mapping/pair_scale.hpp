#pragma once
// A batch's settings are chosen from a few of its scans. A pair whose own
// scans are much larger or smaller than those (a drive from a corridor into
// the open) is searched with the batch's settings scaled by a power of two:
// each pair gets a voxel and a box that fit its own scans, and the pairs of
// one scale still share each scan's preparation.

#include <string>
#include <vector>

#include "boicp/mapping/fusion_memory.hpp"
#include "boicp/mapping/map_pairs.hpp"
#include "boicp/registration/config.hpp"

namespace boicp {

/// What scales a batch's pairs: every scan's typical range and the one its
/// settings were chosen at.
struct BatchScale {
  std::vector<double> scan_ranges;  // each scan's MedianRange, metres; 0 = unknown
  double reference_range = 0.0;     // median MedianRange of the measured scans; 0 = no scaling
  /// The automatic fields that follow the scale (lengths chosen from the scans).
  std::vector<std::string> fields;
};

/// A pair within this factor of the reference range keeps the batch's settings.
constexpr double kSameScaleFactor = 2.0;

/// Median distance of a profile's points from its frame's origin in metres,
/// to the profile's bin width (9 %); 0 for an empty profile.
double MedianRange(const RangeProfile& profile);

/// The batch's scale: each profile's MedianRange, the reference from the
/// `measured` scans (indices into `profiles`) and the length fields among
/// `auto_fields`. No scaling (reference 0) unless "voxel" is among them.
BatchScale MeasureBatchScale(const std::vector<RangeProfile>& profiles,
                             const std::vector<size_t>& measured,
                             const std::vector<std::string>& auto_fields);

/// The power of two the pair's settings are scaled by: 0 while the mean
/// range of its two scans is within kSameScaleFactor of the reference,
/// else log2 of their ratio, rounded. 0 when a range is unknown.
int PairScaleStep(const BatchScale& scale, const PairIndex& pair);

/// Whether scan `index` alone lies outside kSameScaleFactor of the reference.
bool ScanAtAnotherScale(const BatchScale& scale, size_t index);

/// For the user: "3 of 40 scans reach over 2 times nearer or farther than
/// the measured ones (median range 9.8 m); their pairs search at settings
/// scaled to fit", or empty when no scan does (ScanAtAnotherScale).
std::string DescribeScansAtAnotherScale(const BatchScale& scale);

/// `config` with the fields of scale.fields that are lengths (the voxels,
/// the truncation, the translation box) multiplied by 2^step.
BoIcpConfig ScaledConfig(const BoIcpConfig& config, const BatchScale& scale, int step);

}  // namespace boicp
