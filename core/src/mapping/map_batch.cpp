#include "boicp/mapping/map_batch.hpp"

#include "boicp/mapping/occupancy_map.hpp"

namespace boicp {

BatchSettingsChoice ChooseBatchSettings(MapBatch& batch,
                                        const std::vector<RangeProfile>& profiles) {
  BatchSettingsChoice choice =
      ApplyBatchSettings(batch.scans, batch.config, batch.map.occupancy, batch.map_auto);
  batch.map_auto = {false, false};
  std::vector<size_t> measured;
  for (const MeasuredScan& m : choice.measured) measured.push_back(m.scan);
  batch.scale = MeasureBatchScale(profiles, measured, choice.fields);
  ValidateConfig(batch.config);
  ValidateOccupancySettings(batch.map.occupancy);
  return choice;
}

}  // namespace boicp
