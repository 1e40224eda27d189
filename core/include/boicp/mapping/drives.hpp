#pragma once
// A batch of several drives of one place: each drive's scans follow the
// previous drive's in the batch, each drive is chained on its own, and only
// pairs the engine trusts (found by place recognition) join one drive to
// another. A batch without drive starts is one drive.

#include <cstddef>
#include <string>
#include <utility>
#include <vector>

#include "boicp/mapping/map_pairs.hpp"

namespace boicp {

/// The drive of `scan` among drives that start at scans `drive_starts`
/// (each drive's first scan after the first drive's, ascending; empty: one
/// drive). Drive 0 starts at scan 0.
int DriveOf(const std::vector<int>& drive_starts, int scan);

/// The scans of drive `drive` (0-based) of `num_scans`: [first, end).
std::pair<int, int> DriveScans(const std::vector<int>& drive_starts, int num_scans, size_t drive);

/// Scan i onto scan i+1 within each drive of `num_scans` scans: no pair
/// joins the last scan of one drive to the first of the next.
std::vector<PairIndex> ConsecutivePairsOfDrives(int num_scans,
                                                const std::vector<int>& drive_starts);

/// Throws InputError unless `drive_starts` ascend strictly within
/// (0, num_scans) and every drive has at least 2 scans, naming the drive
/// (by `names`, one per drive, when given).
void ValidateDriveStarts(int num_scans, const std::vector<int>& drive_starts,
                         const std::vector<std::string>& names = {});

/// The drives, by index, that no chain of `edges` joins to the first one
/// (scans 0 .. drive_starts[0]-1); empty when every drive is joined.
std::vector<int> DrivesApartFromTheFirst(int num_scans, const std::vector<int>& drive_starts,
                                         const std::vector<PairIndex>& edges);

}  // namespace boicp
