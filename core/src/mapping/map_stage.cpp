#include "boicp/mapping/map_stage.hpp"

namespace boicp {

std::string MapStageName(MapStage stage) {
  switch (stage) {
    case MapStage::kRegistering:
      return "registering";
    case MapStage::kChaining:
      return "chaining";
    case MapStage::kOptimising:
      return "optimising";
    case MapStage::kFusing:
      return "fusing";
    case MapStage::kWriting:
      return "writing";
  }
  return "unknown";
}

}  // namespace boicp
