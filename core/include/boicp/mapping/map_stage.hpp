#pragma once
// The stages of a map job, in the order they run. Their names are what the
// daemon's Job.stage and `boicp watch` show.

#include <string>

namespace boicp {

enum class MapStage {
  kRegistering,  ///< the pairs
  kChaining,     ///< poses along the chain of pairs (no loop closure)
  kOptimising,   ///< a pose graph over the pairs, loop closures included
  kFusing,       ///< every scan into the OctoMap
  kWriting,      ///< the output files
};

/// "registering", "chaining", "optimising", "fusing" or "writing".
std::string MapStageName(MapStage stage);

}  // namespace boicp
