#pragma once
// The stages around the search that every initialiser shares: cropping and
// downsampling once per pair, and the coarse-to-fine ICP that turns a coarse
// initial transform into the final answer. BO-ICP uses them, and so does
// every baseline the bench compares it with, so that methods differ only in
// how they find the initial transform.

#include <optional>
#include <vector>

#include "boicp/icp/alignment_score.hpp"
#include "boicp/icp/icp.hpp"
#include "boicp/icp/nearest_neighbors.hpp"
#include "boicp/icp/preprocess.hpp"
#include "boicp/registration/config.hpp"
#include "boicp/registration/scan_features.hpp"
#include "boicp/util/types.hpp"

namespace boicp {

/// ICP settings of one search evaluation: the config's correspondence gate and
/// iteration cap, converging once a step moves less than 1e-2 voxel and turns
/// less than 1e-3 rad.
IcpOptions SearchIcpOptions(const BoIcpConfig& config);

/// One level of the refinement pyramid.
struct PyramidLevel {
  double voxel = 0.0;           // metres
  Points source;                // at most config.refine_source_points of them (random, seeded)
  NearestNeighborIndex target;  // every point at this voxel
};

/// One scan cropped to [config.min_range, config.max_range], moved so that
/// its centroid is at the origin, and downsampled at every voxel of a pair's
/// pyramid: built once per scan, it serves every pair the scan is in (a
/// drive's scan is in two), since downsampling the same points at the same
/// voxel gives the same cloud. Centred clouds keep their precision and their
/// ICP steps turn about the scan itself, wherever its frame's origin is (a
/// scan exported in a site frame 10^6 m away).
struct ScanPyramid {
  double min_range = 0.0, max_range = 0.0;     // the range limits `cropped` was cut to, metres
  CellOrder order = CellOrder::kFirstReached;  // of every level's points
  Point centre = Point::Zero();  // the cropped scan's centroid, in the scan's frame (metres)
  Points cropped;                // the raw scan within the range limits, minus `centre`
  std::vector<double> voxels;    // metres: the search voxel, then the refinement levels
  std::vector<Points> levels;    // `cropped` downsampled at each of `voxels`
  /// levels[0]'s FPFH features, computed by the first pair that needs them;
  /// copies of the pyramid, which hold the same levels, share them.
  std::shared_ptr<ScanFeatureMemo> features = std::make_shared<ScanFeatureMemo>();
};

/// The voxels of config's pyramid: config.voxel, then halving from
/// config.voxel / 2 down to the refinement voxel (finest last).
std::vector<double> PyramidVoxels(const BoIcpConfig& config);

/// The order of a pyramid's points: Open3D's for the fixed budget, whose
/// answers depend on it, and the faster first-reached order for the ladder.
CellOrder PyramidCellOrder(const BoIcpConfig& config);

/// `raw` cropped and downsampled at every one of PyramidVoxels(config), the
/// levels built on config.threads threads.
ScanPyramid BuildScanPyramid(PointSpan raw, const BoIcpConfig& config);

/// Both clouds of a pair at the search voxel and at every refinement level,
/// built once per pair. Each cloud is centred (ScanPyramid): a point p of the
/// source scan is p - source_centre here, and transforms between the two are
/// CentredTransform and UncentredTransform.
struct PreparedPair {
  Point source_centre = Point::Zero();  // metres, in the source scan's frame
  Point target_centre = Point::Zero();  // metres, in the target scan's frame
  Points search_source;
  NearestNeighborIndex search_target;
  /// Normals of search_target's points for point-to-plane evaluations
  /// (radius 3 search voxels); empty when the config's objective is
  /// point-to-point.
  Points search_target_normals;
  /// Voxels halving from config.voxel / 2 down to the refinement voxel, so
  /// every level starts inside the next level's basin; finest last.
  std::vector<PyramidLevel> pyramid;
};

/// T_target_source between the scans' frames, as a transform between the
/// centred clouds, and back.
Transform CentredTransform(const Point& source_centre, const Point& target_centre,
                           const Transform& T_target_source);
Transform UncentredTransform(const Point& source_centre, const Point& target_centre,
                             const Transform& centred);

/// Throws InputError when a cloud is left with fewer than 3 points at any level.
/// The finer levels' sources are subsampled with `level_seed` (default
/// config.seed), so two searches with different seeds can share their finest
/// points and compare their answers on them.
PreparedPair PreparePair(const Points& source, const Points& target, const BoIcpConfig& config,
                         std::optional<uint64_t> level_seed = std::nullopt);

/// The same from scans' pyramids: a level the pyramid holds at the voxel
/// config asks for is used as it is, any other (a retry's coarser search
/// voxel) is downsampled from the pyramid's cropped scan. The answer is the
/// one PreparePair gives for the scans' raw points. Throws
/// std::invalid_argument when a pyramid was cropped to other range limits
/// than config's.
PreparedPair PreparePair(const ScanPyramid& source, const ScanPyramid& target,
                         const BoIcpConfig& config,
                         std::optional<uint64_t> level_seed = std::nullopt);

/// A refined transform (T_target_source) and how well it fits at the finest
/// level, scored with the config's inlier distance.
struct RefinedAlignment {
  Transform transform = Transform::Identity();
  AlignmentScore score;
  /// 1 - (runner-up's fitness / the answer's fitness) at the finest level, in
  /// [0, 1]: 0 when another basin fits as well, when the answer has no
  /// inliers, or when there was a single start (nothing to compare with).
  /// The runner-up of a lone survivor is the best run abandoned on the way,
  /// scored where it stopped; 1 when every start met the answer's basin.
  double margin = 1.0;
  /// The angle that moves a finest-level source point at the cloud's RMS
  /// radius by one refinement voxel, degrees: how finely that level can
  /// resolve the rotation.
  double resolution_deg = 0.0;
  /// True when the margin compared the answer with other starts (two or
  /// more, and the answer has inliers): a margin of 0 is then a tie.
  bool margin_measured = false;
};

/// Coarse-to-fine point-to-point ICP from each of `starts` (T_target_source,
/// best guess first; at least one): the search clouds with a 1.5 voxel gate,
/// then each pyramid level with a gate of 3 of its voxels. At every level the
/// leader (the best truncated mean so far, clipped at 1.5 voxels of the level)
/// runs first, and the others are abandoned only once they head for a clearly
/// worse fit (kClearlyWorse times the leader's), so a wrong basin costs a few
/// coarse iterations while a near tie reaches the finest level. Runs that meet
/// (within one voxel of the level and 1 degree) continue as one. Of the basins
/// that reach the finest level, the one with the largest inlier fraction
/// wins: the coarse scores of a low-overlap pair's true basin and of a wrong
/// one can differ by less than their noise, while the fine fit tells them apart.
/// Under Budget::kAuto the runs extrapolate (IcpOptions::extrapolate).
constexpr double kClearlyWorse = 1.3;

RefinedAlignment RefineCoarseToFine(const std::vector<Transform>& starts, const PreparedPair& pair,
                                    const BoIcpConfig& config);

}  // namespace boicp
