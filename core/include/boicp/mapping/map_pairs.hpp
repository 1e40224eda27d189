#pragma once
// Which pairs of a scan batch get registered: consecutive scans, keyframes
// chosen by overlap (as in the BO-ICP paper), or an explicit list (how loop
// closures come in), and the seed each pair's search uses.

#include <cstdint>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "boicp/io/point_cloud_io.hpp"
#include "boicp/registration/config.hpp"

namespace boicp {

/// One registration of a batch, by index into the batch's scan list. The
/// registration estimates T_target_source.
struct PairIndex {
  int source = 0;
  int target = 0;
  bool operator==(const PairIndex& other) const {
    return source == other.source && target == other.target;
  }
  bool operator<(const PairIndex& other) const {
    return source != other.source ? source < other.source : target < other.target;
  }
};

/// "source->target", as logs and progress name a pair.
std::string PairName(const PairIndex& p);

/// Scan i (source) onto scan i+1 (target) for every i < num_scans - 1, the
/// direction of the shared data's pairs.csv.
std::vector<PairIndex> ConsecutivePairs(int num_scans);

/// For each of `num_scans` scans, the smallest index of the scans that
/// `pairs` connect it to, however indirectly (its own when none): scans with
/// one label form one connected part. Precondition: indices in range.
std::vector<int> ConnectedParts(int num_scans, const std::vector<PairIndex>& pairs);

/// Throws InputError naming the first bad pair: an index outside
/// [0, num_scans), a scan paired with itself, or a pair given twice (in
/// either direction). With `require_connected`, also throws unless the pairs
/// connect every scan, naming a scan that no chain of pairs reaches from scan 0.
void ValidatePairs(int num_scans, const std::vector<PairIndex>& pairs, bool require_connected);

/// Which pairs a batch registers, decided once for the daemon and `boicp
/// map` alike. A fixed plan registers `chain` and `extras`, all known up
/// front; a keyframe plan (PlanKeyframes) grows its chain from the
/// registrations' overlap estimates (KeyframePlanner) and registers
/// `extras` besides.
struct PairingPlan {
  bool keyframes = false;
  double overlap_threshold = 0.7;  // keyframes only, in (0, 1]
  std::vector<PairIndex> chain;    // fixed plans: chained first into poses
  std::vector<PairIndex> extras;   // loop closures on top of the chain
  /// Extras the map found (bridges and loop candidates), each with the
  /// T_target_source its search is centred on: the chained poses', or a
  /// place match's heading.
  std::map<PairIndex, Transform> found_priors;
  /// Of those, the bridges over doubtful chain pairs; the others are loop
  /// candidates.
  std::set<PairIndex> bridges;
  /// Of the loop candidates, those found by place recognition; the others
  /// were found on the chained poses.
  std::set<PairIndex> places;
};

/// A fixed plan: `chain` (consecutive or explicit pairs) plus `extras`.
PairingPlan PlanFixedPairs(std::vector<PairIndex> chain, std::vector<PairIndex> extras = {});

/// A keyframe plan with the given overlap threshold, plus `extras`.
PairingPlan PlanKeyframes(double overlap_threshold, std::vector<PairIndex> extras = {});

/// The search seed of one pair: a SplitMix64 mix of the job seed and the two
/// indices. It depends on nothing else, so a batch that is resumed or
/// scheduled differently gives every pair the same result.
uint64_t PairSeed(uint64_t job_seed, const PairIndex& pair);

/// The paper's overlap thresholds for keyframes: 0.6 for a depth camera, 0.7
/// for a LiDAR and every other sensor.
double DefaultOverlapThreshold(SensorKind sensor);

/// Keyframe selection by overlap. Every scan j after the current keyframe k
/// is registered onto it (pair source = j, target = k) and its overlap is
/// the registration's overlap estimate (RegistrationResult::overlap: the
/// fraction of j within 1.5 search voxels of k; raw fitness counts only
/// points within the tight inlier distance, so sensor noise and a loose fine
/// alignment lower it without less being seen). While the overlap stays at
/// or above the threshold the scan hangs off k. When scan j falls below it,
/// scan j-1 becomes the next keyframe and j is registered onto that one
/// instead (the probe j -> k is dropped). A doubtful probe counts as too
/// little overlap. A scan adjacent to its keyframe is always kept, however
/// small its overlap, so the chain never breaks.
///
/// A keyframe also reaches only so far. Its search box does not follow the
/// drive (without priors it is centred on the clouds' centroids, which lag
/// the motion when a scan sees more on one side), so once a scan hangs off k
/// more than kMaxKeyframeReach into its box, the next scan, a step further,
/// may lie outside and look right anyway. That scan becomes the keyframe.
///
/// Decisions depend only on the outcomes recorded, never on the order they
/// arrive in, so a resumed batch makes the same choices. Probes can run
/// ahead (NextProbes); those beyond a keyframe change are wasted but harmless.
class KeyframePlanner {
 public:
  /// Preconditions: num_scans >= 1, overlap_threshold in (0, 1].
  KeyframePlanner(int num_scans, double overlap_threshold);

  /// Up to `max_count` probes not handed out before, all onto the current
  /// keyframe, in scan order. Empty when the plan needs results first or is done.
  std::vector<PairIndex> NextProbes(int max_count);

  /// What the planner reads of a finished probe.
  struct ProbeOutcome {
    /// Overlap estimate in [0, 1] (results stored before overlap was
    /// computed pass their fitness).
    double overlap = 0.0;
    double search_reach = 0.0;  // RegistrationResult::search_reach
    bool doubtful = false;
  };

  /// Half the box: a drive's next scan is then still inside it as long as
  /// scans are less than half the translation bounds apart.
  static constexpr double kMaxKeyframeReach = 0.5;

  /// Records a finished probe and advances the plan as far as the recorded
  /// results allow. Results for pairs the plan no longer needs are kept but
  /// change nothing.
  void Record(const PairIndex& pair, const ProbeOutcome& outcome);

  /// True once every scan hangs off a keyframe.
  bool Done() const { return next_ >= num_scans_; }

  /// The pairs that form the chain so far (one per scan after the first).
  const std::vector<PairIndex>& ChainPairs() const { return chain_; }

 private:
  void Advance();

  int num_scans_;
  double threshold_;
  int keyframe_ = 0;
  int next_ = 1;        // first scan not yet attached
  int next_probe_ = 1;  // first scan not yet handed out as a probe onto keyframe_
  std::map<PairIndex, ProbeOutcome> outcomes_;
  std::vector<PairIndex> chain_;
};

}  // namespace boicp
