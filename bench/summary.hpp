#pragma once
// summary.md: the run's conditions and one table per dataset.

#include <cstdint>
#include <string>
#include <vector>

#include "dataset_table.hpp"
#include "machine_info.hpp"
#include "result_row.hpp"

namespace boicp::bench {

struct RunInfo {
  MachineInfo machine;
  int threads = 1;
  uint64_t seed = 1;
  bool quick = false;
  std::string command_line;
  std::string started_utc;
  std::vector<DatasetSettings> datasets;
  std::vector<std::string> method_lines;  // DescribeMethods
  std::string scaling_line;               // empty when no scaling study ran
  double wall_s = 0.0;                    // of the whole run so far
  std::string load_average_end;           // /proc/loadavg when the run finished
};

/// Machine, thread budget, seeds, per-dataset settings and method budgets.
std::string FormatRunConditions(const RunInfo& info);

/// Per dataset and method (suite rows): pairs, median and mean wall time,
/// rotation and translation error, success rate; then the scaling rows.
std::string FormatSummary(const RunInfo& info, const std::vector<ResultRow>& rows);

}  // namespace boicp::bench
