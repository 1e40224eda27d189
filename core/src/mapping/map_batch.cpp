#include "boicp/mapping/map_batch.hpp"

#include "boicp/mapping/occupancy_map.hpp"

namespace boicp {

BatchSettingsChoice ChooseBatchSettings(MapBatch& batch) {
  BatchSettingsChoice choice =
      ApplyBatchSettings(batch.scans, batch.config, batch.map.occupancy, batch.map_auto);
  batch.map_auto = {false, false};
  ValidateConfig(batch.config);
  ValidateOccupancySettings(batch.map.occupancy);
  return choice;
}

}  // namespace boicp
