#include "boicp/mapping/occupancy_map.hpp"

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <unordered_map>
#include <vector>

#include <octomap/OcTree.h>

#include "boicp/util/parallel_for.hpp"
#include "mapping/octree_file.hpp"
#include "stoppable_output.hpp"

namespace boicp {
namespace {

using octomap::KeySet;
using octomap::OcTreeKey;
using octomap::point3d;

void RequireValidMapSettings(bool ok, const std::string& message) {
  if (!ok) throw InputError("map settings: " + message);
}

// How often long loops poll a stop request: a ray crosses up to tens of
// thousands of cells, a tree update touches one node per cell, and either
// count keeps a stop within a small fraction of a second of its request.
constexpr size_t kRaysPerStopPoll = 64;
constexpr size_t kCellsPerStopPoll = 16384;

// Heap bytes per element, allocator overhead included: a bitmap block and
// its hash-map node, an occupied key's hash-set node, and a tree node with
// its share of a parent's eight child pointers (a leaf of a sparse tree may
// be the only child of every parent up the path; the tree rarely is).
constexpr size_t kBlockBytes = 560;
constexpr size_t kKeyBytes = 56;
constexpr size_t kTreeNodeBytes = 64;

// A stop request shared by the threads of one ray cast, and the bytes their
// cells take: the first to see the request fired, or the bytes over their
// limit, tells the others, which then return at their next poll.
class SharedStop {
 public:
  SharedStop(const MapStopRequest& request, size_t max_bytes)
      : request_(request), max_bytes_(max_bytes) {}

  bool Poll() {
    if (fired_.load(std::memory_order_relaxed)) return true;
    if (request_ && request_()) fired_.store(true, std::memory_order_relaxed);
    return fired_.load(std::memory_order_relaxed);
  }

  // Counts `bytes` more; past the limit, stops every thread.
  void Take(size_t bytes) {
    if (bytes == 0 || max_bytes_ == 0) return;
    if (taken_.fetch_add(bytes, std::memory_order_relaxed) + bytes > max_bytes_) {
      over_limit_.store(true, std::memory_order_relaxed);
      fired_.store(true, std::memory_order_relaxed);
    }
  }

  bool fired() const { return fired_.load(std::memory_order_relaxed); }
  bool over_limit() const { return over_limit_.load(std::memory_order_relaxed); }

 private:
  const MapStopRequest& request_;
  const size_t max_bytes_;
  std::atomic<size_t> taken_{0};
  std::atomic<bool> fired_{false};
  std::atomic<bool> over_limit_{false};
};

// An OcTree whose updates skip OctoMap's early-abort search. updateNode
// first searches the key and returns if its leaf is already clamped in the
// update's direction; otherwise it descends again to update. The second
// descent alone gives the same tree: a clamped leaf updated the same way is
// clamped back to the same value, and its path already exists. That saves
// one of the two descents per cell, about half of the tree update.
class FusionOcTree : public octomap::OcTree {
 public:
  using octomap::OcTree::OcTree;

  void Update(const OcTreeKey& key, bool occupied) {
    const float log_odds = occupied ? prob_hit_log : prob_miss_log;
    bool created_root = false;
    if (root == nullptr) {
      root = new octomap::OcTreeNode();
      ++tree_size;
      created_root = true;
    }
    updateNodeRecurs(root, created_root, key, 0, log_odds, /*lazy_eval=*/true);
  }
};

// A set of cells as bitmaps of 16 x 16 x 16-cell blocks. A ray marks
// millions of cells, mostly repeats near the sensor; setting a bit in the
// block the ray is already in costs far less than a hash-set insertion, and
// memory stays in proportion to the blocks touched.
class CellSet {
 public:
  using BlockId = uint64_t;
  using Block = std::array<uint64_t, 64>;  // 4096 bits

  static BlockId BlockOf(const OcTreeKey& key) {
    return (static_cast<BlockId>(key[0] >> 4) << 24) | (static_cast<BlockId>(key[1] >> 4) << 12) |
           static_cast<BlockId>(key[2] >> 4);
  }

  // Returns true when the key's block is new.
  bool Insert(const OcTreeKey& key) {
    const BlockId id = BlockOf(key);
    bool created = false;
    if (id != last_id_ || last_ == nullptr) {
      const auto [block, inserted] = blocks_.try_emplace(id);  // value-initialised: all bits clear
      last_ = &block->second;
      last_id_ = id;
      created = inserted;
    }
    const unsigned bit = BitOf(key);
    (*last_)[bit >> 6] |= uint64_t{1} << (bit & 63);
    return created;
  }

  void Erase(const OcTreeKey& key) {
    const auto it = blocks_.find(BlockOf(key));
    if (it == blocks_.end()) return;
    const unsigned bit = BitOf(key);
    it->second[bit >> 6] &= ~(uint64_t{1} << (bit & 63));
  }

  void UniteWith(const CellSet& other) {
    for (const auto& [id, block] : other.blocks_) {
      Block& mine = blocks_[id];
      for (size_t w = 0; w < mine.size(); ++w) mine[w] |= block[w];
    }
    last_ = nullptr;
  }

  size_t Blocks() const { return blocks_.size(); }

  size_t Count() const {
    size_t count = 0;
    for (const auto& entry : blocks_) {
      for (const uint64_t word : entry.second)
        count += static_cast<size_t>(__builtin_popcountll(word));
    }
    return count;
  }

  template <typename Visit>
  void ForEach(Visit visit) const {
    for (const auto& [id, block] : blocks_) {
      for (size_t w = 0; w < block.size(); ++w) {
        for (uint64_t word = block[w]; word != 0; word &= word - 1) {
          const unsigned bit =
              static_cast<unsigned>(w * 64) + static_cast<unsigned>(__builtin_ctzll(word));
          visit(KeyOf(id, bit));
        }
      }
    }
  }

 private:
  static unsigned BitOf(const OcTreeKey& key) {
    return (static_cast<unsigned>(key[0] & 15) << 8) | (static_cast<unsigned>(key[1] & 15) << 4) |
           static_cast<unsigned>(key[2] & 15);
  }
  static OcTreeKey KeyOf(BlockId id, unsigned bit) {
    const auto coordinate = [&](int shift_id, int shift_bit) {
      return static_cast<octomap::key_type>((((id >> shift_id) & 0xFFF) << 4) |
                                            ((bit >> shift_bit) & 15));
    };
    return OcTreeKey(coordinate(24, 8), coordinate(12, 4), coordinate(0, 0));
  }

  std::unordered_map<BlockId, Block> blocks_;
  BlockId last_id_ = 0;
  Block* last_ = nullptr;  // the block of the last insertion (element pointers are stable)
};

// Which of `shards` sets a block's cells belong to, so that each shard is
// merged on its own thread. The block id is mixed first: neighbouring
// blocks should land in different shards.
size_t ShardOf(CellSet::BlockId block, size_t shards) {
  return static_cast<size_t>((block * 0x9E3779B97F4A7C15ull) >> 40) % shards;
}

// Free and occupied cells, each split into shards by the cell's block.
struct ShardedCells {
  explicit ShardedCells(size_t shards) : free(shards), occupied(shards) {}
  std::vector<CellSet> free;
  std::vector<KeySet> occupied;
};

// The scan in the map frame, in OctoMap's single precision.
octomap::Pointcloud ToMapFrame(const Points& points, const Transform& T_map_scan) {
  const Eigen::Matrix3d R = T_map_scan.topLeftCorner<3, 3>();
  const Eigen::Vector3d t = T_map_scan.topRightCorner<3, 1>();
  octomap::Pointcloud cloud;
  cloud.reserve(points.size());
  for (const Point& p : points) {
    const Point q = R * p + t;
    cloud.push_back(static_cast<float>(q.x()), static_cast<float>(q.y()),
                    static_cast<float>(q.z()));
  }
  return cloud;
}

// One endpoint per leaf, at the leaf's centre: OctoMap's discretised
// insertion (computeDiscreteUpdate), which casts one ray per leaf hit. A
// point beyond the tree's key range (2^15 leaves from the origin each way)
// would wrap to a key on the far side: it is left out and counted instead.
std::vector<point3d> DiscretisedEndpoints(const octomap::OcTree& tree,
                                          const octomap::Pointcloud& cloud, size_t& out_of_range) {
  KeySet leaves;
  std::vector<point3d> endpoints;
  endpoints.reserve(cloud.size());
  for (size_t i = 0; i < cloud.size(); ++i) {
    OcTreeKey key;
    if (!tree.coordToKeyChecked(cloud[i], key)) {
      ++out_of_range;
    } else if (leaves.insert(key).second) {
      endpoints.push_back(tree.keyToCoord(key));
    }
  }
  return endpoints;
}

// Casts the rays to endpoints [begin, end) as OctoMap's computeUpdate does
// without a bounding box: cells along a ray are free, its endpoint occupied;
// a ray longer than max_range (when >= 0) is cut there and marks no endpoint.
// Returns early, with the cells incomplete, once `stop` fires.
void CastRays(const octomap::OcTree& tree, const std::vector<point3d>& endpoints, size_t begin,
              size_t end, const point3d& origin, double max_range, ShardedCells& cells,
              SharedStop& stop) {
  const size_t shards = cells.free.size();
  octomap::KeyRay ray;
  const auto mark_free = [&] {
    size_t new_blocks = 0;
    for (const OcTreeKey& key : ray) {
      new_blocks +=
          cells.free[shards == 1 ? 0 : ShardOf(CellSet::BlockOf(key), shards)].Insert(key);
    }
    stop.Take(new_blocks * kBlockBytes);
  };
  for (size_t i = begin; i < end; ++i) {
    if ((i - begin) % kRaysPerStopPoll == 0 && stop.Poll()) return;
    const point3d& p = endpoints[i];
    if (max_range < 0.0 || (p - origin).norm() <= max_range) {
      if (tree.computeRayKeys(origin, p, ray)) mark_free();
      OcTreeKey key;
      if (tree.coordToKeyChecked(p, key) &&
          cells.occupied[ShardOf(CellSet::BlockOf(key), shards)].insert(key).second) {
        stop.Take(kKeyBytes);
      }
    } else {
      const point3d direction = (p - origin).normalized();
      const point3d cut_end = origin + direction * static_cast<float>(max_range);
      if (tree.computeRayKeys(origin, cut_end, ray)) mark_free();
    }
  }
}

// Unites shard `shard` of every chunk's cells into `merged`, then drops from
// the free cells those also occupied (OctoMap prefers occupied).
void MergeShard(std::vector<ShardedCells>& chunks, size_t shard, ShardedCells& merged) {
  CellSet& free = merged.free[shard];
  KeySet& occupied = merged.occupied[shard];
  free = std::move(chunks[0].free[shard]);
  occupied = std::move(chunks[0].occupied[shard]);
  for (size_t c = 1; c < chunks.size(); ++c) {
    free.UniteWith(chunks[c].free[shard]);
    occupied.insert(chunks[c].occupied[shard].begin(), chunks[c].occupied[shard].end());
    chunks[c].free[shard] = CellSet();
    KeySet().swap(chunks[c].occupied[shard]);
  }
  for (const OcTreeKey& key : occupied) free.Erase(key);
}

}  // namespace

struct ScanUpdate::Impl {
  explicit Impl(size_t shards) : cells(shards) {}
  ShardedCells cells;       // free and occupied are disjoint
  size_t out_of_range = 0;  // points left out: beyond the tree's key range
};

ScanUpdate::ScanUpdate() : impl_(std::make_unique<Impl>(1)) {}
ScanUpdate::~ScanUpdate() = default;
ScanUpdate::ScanUpdate(ScanUpdate&&) noexcept = default;
ScanUpdate& ScanUpdate::operator=(ScanUpdate&&) noexcept = default;

size_t ScanUpdate::FreeCells() const {
  size_t count = 0;
  for (const CellSet& shard : impl_->cells.free) count += shard.Count();
  return count;
}

size_t ScanUpdate::OccupiedCells() const {
  size_t count = 0;
  for (const KeySet& shard : impl_->cells.occupied) count += shard.size();
  return count;
}

size_t ScanUpdate::PointsOutOfRange() const { return impl_->out_of_range; }

size_t ScanUpdate::Bytes() const {
  size_t blocks = 0;
  for (const CellSet& shard : impl_->cells.free) blocks += shard.Blocks();
  return blocks * kBlockBytes + OccupiedCells() * kKeyBytes;
}

struct OccupancyMap::Impl {
  Impl(const OccupancySettings& s, size_t max_bytes)
      : settings(s), max_tree_bytes(max_bytes), tree(s.resolution) {
    tree.setProbHit(s.prob_hit);
    tree.setProbMiss(s.prob_miss);
    tree.setClampingThresMin(s.clamp_min);
    tree.setClampingThresMax(s.clamp_max);
  }
  OccupancySettings settings;
  size_t max_tree_bytes;  // 0 = no cap
  FusionOcTree tree;
  bool inner_dirty = false;  // lazy insertion leaves inner nodes stale until updated

  void UpdateInner() {
    if (!inner_dirty) return;
    tree.updateInnerOccupancy();
    inner_dirty = false;
  }
};

void ValidateOccupancySettings(const OccupancySettings& s) {
  RequireValidMapSettings(
      std::isfinite(s.resolution) && s.resolution >= 0.001 && s.resolution <= 100.0,
      "resolution must be between 0.001 and 100 m");
  RequireValidMapSettings(std::isfinite(s.max_range) && s.max_range >= 0.0,
                          "max_range must be >= 0 (0 = no limit)");
  RequireValidMapSettings(s.prob_hit > 0.5 && s.prob_hit < 1.0, "prob_hit must be in (0.5, 1)");
  RequireValidMapSettings(s.prob_miss > 0.0 && s.prob_miss < 0.5, "prob_miss must be in (0, 0.5)");
  RequireValidMapSettings(s.clamp_min > 0.0 && s.clamp_min < s.clamp_max && s.clamp_max < 1.0,
                          "clamping thresholds must satisfy 0 < clamp_min < clamp_max < 1");
}

OccupancyMap::OccupancyMap(const OccupancySettings& settings, size_t max_tree_bytes) {
  ValidateOccupancySettings(settings);
  impl_ = std::make_unique<Impl>(settings, max_tree_bytes);
}

OccupancyMap::~OccupancyMap() = default;

void OccupancyMap::InsertScan(const Points& points, const Transform& T_map_scan,
                              const Point& sensor_origin) {
  ApplyUpdate(ComputeUpdate(points, T_map_scan, sensor_origin, 1));
}

ScanUpdate OccupancyMap::ComputeUpdate(const Points& points, const Transform& T_map_scan,
                                       const Point& sensor_origin, int threads,
                                       const MapStopRequest& stop, size_t max_bytes) const {
  const octomap::OcTree& tree = impl_->tree;
  size_t out_of_range = 0;
  const std::vector<point3d> endpoints =
      DiscretisedEndpoints(tree, ToMapFrame(points, T_map_scan), out_of_range);
  const Point origin_d =
      T_map_scan.topLeftCorner<3, 3>() * sensor_origin + T_map_scan.topRightCorner<3, 1>();
  const point3d origin(static_cast<float>(origin_d.x()), static_cast<float>(origin_d.y()),
                       static_cast<float>(origin_d.z()));
  const double max_range = impl_->settings.max_range > 0.0 ? impl_->settings.max_range : -1.0;

  const size_t workers = static_cast<size_t>(std::max(threads, 1));
  const size_t chunk_count = std::max<size_t>(1, std::min(workers, endpoints.size()));
  const size_t shards = workers;
  std::vector<ShardedCells> chunks(chunk_count, ShardedCells(shards));
  SharedStop shared_stop(stop, max_bytes);
  ParallelFor(chunk_count, threads, [&](size_t c) {
    const size_t begin = endpoints.size() * c / chunk_count;
    const size_t end = endpoints.size() * (c + 1) / chunk_count;
    CastRays(tree, endpoints, begin, end, origin, max_range, chunks[c], shared_stop);
  });
  if (shared_stop.over_limit()) {
    throw LimitExceeded("the rays of one scan cross cells that take more than " +
                        std::to_string(max_bytes >> 20) + " MB");
  }
  if (shared_stop.fired()) throw Cancelled();

  ScanUpdate update;
  update.impl_ = std::make_unique<ScanUpdate::Impl>(shards);
  update.impl_->out_of_range = out_of_range;
  ParallelFor(shards, threads, [&](size_t s) { MergeShard(chunks, s, update.impl_->cells); });
  return update;
}

void OccupancyMap::ApplyUpdate(const ScanUpdate& update, const MapStopRequest& stop) {
  FusionOcTree& tree = impl_->tree;
  impl_->inner_dirty = true;
  size_t cells = 0;
  const auto update_cell = [&](const OcTreeKey& key, bool occupied) {
    if (++cells % kCellsPerStopPoll == 0) {
      if (stop && stop()) throw Cancelled();
      if (impl_->max_tree_bytes != 0 && TreeBytes() > impl_->max_tree_bytes) {
        throw LimitExceeded("the map's tree takes more than " +
                            std::to_string(impl_->max_tree_bytes >> 20) + " MB");
      }
    }
    tree.Update(key, occupied);
  };
  for (const CellSet& shard : update.impl_->cells.free) {
    shard.ForEach([&](const OcTreeKey& key) { update_cell(key, /*occupied=*/false); });
  }
  for (const KeySet& shard : update.impl_->cells.occupied) {
    for (const OcTreeKey& key : shard) update_cell(key, /*occupied=*/true);
  }
}

size_t OccupancyMap::TreeBytes() const { return impl_->tree.size() * kTreeNodeBytes; }

size_t OccupancyMap::OccupiedLeaves() {
  impl_->UpdateInner();
  size_t count = 0;
  for (auto it = impl_->tree.begin_leafs(), end = impl_->tree.end_leafs(); it != end; ++it) {
    if (impl_->tree.isNodeOccupied(*it)) ++count;
  }
  return count;
}

namespace {

// Writes through streams, because OctoMap's file-name overloads print
// progress to stdout, which is the daemon's log.
void WriteTree(const std::string& path, const std::string& kind, const MapStopRequest& stop,
               const std::function<bool(std::ostream&)>& write) {
  std::filebuf file;
  if (!file.open(path, std::ios::out | std::ios::binary | std::ios::trunc)) {
    throw std::runtime_error(path + ": cannot write OctoMap " + kind);
  }
  StoppableOutput stoppable(file, stop);
  std::ostream out(&stoppable);
  const bool written = write(out) && out.flush();
  if (stoppable.stopped()) throw Cancelled();
  if (!written || file.close() == nullptr) {
    throw std::runtime_error(path + ": cannot write OctoMap " + kind);
  }
}

}  // namespace

void OccupancyMap::WriteFull(const std::string& path, const MapStopRequest& stop) {
  impl_->UpdateInner();
  WriteTree(path, ".ot", stop, [&](std::ostream& out) { return impl_->tree.write(out); });
}

void OccupancyMap::WriteBinary(const std::string& path, const MapStopRequest& stop) {
  impl_->UpdateInner();
  WriteTree(path, ".bt", stop,
            [&](std::ostream& out) { return WriteBinaryOctree(impl_->tree, out); });
}

}  // namespace boicp
