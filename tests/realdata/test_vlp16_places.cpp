// Place recognition on the real VLP-16 drive in ../shared/data/vlp16_loop:
// the map's own loop search (ViewScans, LoopCandidatesFromPlaces, with the
// defaults) proposes the drive's two revisit stretches, at the headings of
// their revisits.csv rows. The drive has no reference poses; revisits.csv
// was found by a Scan Context ranking checked by ICP, so this test shows
// that the map's search finds what that check confirmed, within its budget.

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "boicp/mapping/loop_candidates.hpp"
#include "boicp/mapping/map_pipeline.hpp"
#include "shared_data.hpp"

namespace boicp {
namespace {

namespace fs = std::filesystem;

struct Revisit {
  int earlier = 0;  // batch indices
  int later = 0;
  double yaw_deg = 0.0;  // later into earlier
};

// The confirmed rows ("revisit") of revisits.csv, by batch index.
std::vector<Revisit> ConfirmedRevisits(const fs::path& csv,
                                       const std::map<std::string, int>& index) {
  std::ifstream in(csv);
  std::string line;
  std::getline(in, line);  // header
  std::vector<Revisit> revisits;
  while (std::getline(in, line)) {
    std::vector<std::string> cells;
    std::stringstream row(line);
    for (std::string cell; std::getline(row, cell, ',');) cells.push_back(cell);
    if (cells.size() < 9 || cells[8] != "revisit") continue;
    revisits.push_back({index.at(cells[0]), index.at(cells[1]), std::stod(cells[7])});
  }
  return revisits;
}

TEST(Vlp16Places, TheMapsLoopSearchProposesBothRevisitStretches) {
  const fs::path folder = SharedDataFolder("vlp16_loop");
  if (!fs::exists(folder / "revisits.csv")) {
    GTEST_SKIP() << "real data not found at " << folder.string()
                 << " (../shared/data beside the project root); skipping";
  }
  std::vector<fs::path> files;
  for (const auto& entry : fs::directory_iterator(folder / "pcd")) files.push_back(entry.path());
  std::sort(files.begin(), files.end());
  std::vector<ScanSource> scans;
  std::map<std::string, int> index;
  for (const fs::path& file : files) {
    index[file.filename().string()] = static_cast<int>(scans.size());
    ScanSource scan;
    scan.path = file.string();
    scans.push_back(scan);
  }
  const std::vector<Revisit> revisits = ConfirmedRevisits(folder / "revisits.csv", index);
  ASSERT_EQ(revisits.size(), 12u);

  const ScanViews views =
      ViewScans(scans, std::vector<Transform>(scans.size(), Transform::Identity()));
  // Every scan a piece of its own, as if no pair were trusted: the search
  // alone, over the whole drive.
  std::vector<int> pieces(scans.size());
  for (size_t i = 0; i < pieces.size(); ++i) pieces[i] = static_cast<int>(i);
  const LoopCandidateOptions options;
  const std::vector<LoopCandidate> found =
      LoopCandidatesFromPlaces(views.places, views.sensor_origins, pieces, {}, options);
  EXPECT_EQ(found.size(), static_cast<size_t>(options.max_place_per_drive_scan * scans.size()));

  // The two stretches the drive passes again (PROVENANCE.txt): scans 376-387
  // come back to 3-21, and 425-437 pass 133-211 again.
  const auto in = [&](int i, const char* from, const char* to) {
    return i >= index.at(from) && i <= index.at(to);
  };
  int back_to_start = 0, second_pass = 0, on_a_row = 0;
  for (const LoopCandidate& c : found) {
    back_to_start += in(c.pair.source, "000376.pcd", "000387.pcd") &&
                     in(c.pair.target, "000003.pcd", "000021.pcd");
    second_pass += in(c.pair.source, "000411.pcd", "000437.pcd") &&
                   in(c.pair.target, "000132.pcd", "000211.pcd");
    for (const Revisit& r : revisits) {
      if (std::abs(c.pair.source - r.later) > 1 || std::abs(c.pair.target - r.earlier) > 1)
        continue;
      ++on_a_row;
      // The rows' yaw maps the later scan into the earlier: T_target_source's.
      const double yaw_deg = std::atan2(c.prior(1, 0), c.prior(0, 0)) * 180.0 / M_PI;
      EXPECT_LE(std::abs(std::remainder(yaw_deg - r.yaw_deg, 360.0)), 12.0)
          << PairName(c.pair) << " against the row's " << r.yaw_deg << " degrees";
    }
  }
  std::fprintf(stderr,
               "VLP-16: %zu place candidates, %d back at the start, %d on the second pass, %d "
               "within a scan of a confirmed revisit\n",
               found.size(), back_to_start, second_pass, on_a_row);
  EXPECT_GE(back_to_start, 1);
  EXPECT_GE(second_pass, 1);
}

}  // namespace
}  // namespace boicp
