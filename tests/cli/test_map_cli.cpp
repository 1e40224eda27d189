// `boicp map` and `boicp preview` as a script sees them: every output file,
// reruns that reuse finished pairs, one-line errors with exit code 2, the
// real KITTI folder, and the same trajectory as the daemon for the same
// seed, config and pairing (consecutive, overlap and explicit).

#include <octomap/OcTree.h>
#include <sys/wait.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <memory>
#include <random>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <open3d/geometry/Image.h>
#include <open3d/io/ImageIO.h>
#include <nlohmann/json.hpp>

#include "boicp/io/point_cloud_io.hpp"
#include "boicp/io/scan_folder.hpp"
#include "boicp/io/synthetic_scene.hpp"
#include "boicp/io/trajectory_io.hpp"
#include "boicp/mapping/map_pipeline.hpp"
#include "boicp/registration/bo_icp.hpp"

#ifdef BOICP_TEST_WITH_DAEMON
#include "../support/files_and_processes.hpp"
#include "boicp/rpc/map_builder_client.hpp"
#include "daemon_process.hpp"
#endif

#ifndef BOICP_SHARED_DATA_DIR
#define BOICP_SHARED_DATA_DIR ""
#endif

namespace boicp {
namespace {
using boicp::test::RunCaptured;
using boicp::test::RunResult;
using boicp::test::Slurp;

using ::testing::HasSubstr;
using ::testing::Not;
namespace fs = std::filesystem;
using nlohmann::json;

// Small and quick: preset A cut to 4 + 4 evaluations a stage, ground-vehicle
// rotation bounds (the generated scans overlap so much that this is exact).
std::string Quick(int seed = 5) {
  return " --config A --random-samples 4 --iterations 4 --rotation-bounds 0.2,0.2,3.14159"
         " --resolution 0.3 --seed " +
         std::to_string(seed);
}

int CountLines(const std::string& text) {
  int lines = 0;
  for (char c : text) lines += c == '\n';
  return lines;
}

// Distinct colours on a grid of samples: a blank picture has one or two.
size_t DistinctColours(const fs::path& png) {
  open3d::geometry::Image image;
  if (!open3d::io::ReadImage(png.string(), image) || image.num_of_channels_ != 3) return 0;
  std::set<std::array<uint8_t, 3>> colours;
  for (int y = 0; y < image.height_; y += 4) {
    for (int x = 0; x < image.width_; x += 4) {
      const uint8_t* p = image.PointerAt<uint8_t>(x, y, 0);
      colours.insert({p[0], p[1], p[2]});
    }
  }
  return colours.size();
}

class MapCli : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("boicp_map_cli_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  RunResult Run(const std::string& args) {
    return RunCaptured(std::string(BOICP_CLI_PATH) + " " + args, dir_);
  }

  // A generated drive of `n` .xyz scans, 2 m apart with a gentle turn.
  fs::path MakeDrive(int n) {
    const fs::path scans = dir_ / "drive";
    fs::create_directories(scans);
    const Points world = MakeSyntheticStreet(11);
    for (int i = 0; i < n; ++i) {
      const Transform pose = PoseFromYawTranslation(0.04 * i, {-5.0 + 2.0 * i, 0.3 * i, 1.8});
      truth_.push_back(pose);
      char name[32];
      std::snprintf(name, sizeof(name), "scan%03d.xyz", i);
      WriteXyz((scans / name).string(), SimulateScan(world, pose, 30.0, 0.02, 100 + i));
    }
    return scans;
  }

  // MakeDrive(6) with scan 3 replaced by noise that no other scan matches.
  fs::path MakeDriveWithNoiseAt3() {
    const fs::path scans = MakeDrive(6);
    Points noise;
    std::mt19937 random(3);
    std::uniform_real_distribution<double> coordinate(-20.0, 20.0);
    for (int i = 0; i < 4000; ++i) {
      noise.emplace_back(coordinate(random), coordinate(random), 0.1 * coordinate(random));
    }
    WriteXyz((scans / "scan003.xyz").string(), noise);
    return scans;
  }

  // Moves MakeDrive's scans from `first` on into a folder `name` of their
  // own: a second drive of the same street.
  fs::path SplitDrive(const fs::path& drive, int first, const std::string& name) {
    const fs::path second = dir_ / name;
    fs::create_directories(second);
    for (size_t i = static_cast<size_t>(first); i < truth_.size(); ++i) {
      char file[32];
      std::snprintf(file, sizeof(file), "scan%03zu.xyz", i);
      fs::rename(drive / file, second / file);
    }
    return second;
  }

  fs::path dir_;
  std::vector<Transform> truth_;  // T_world_scan of MakeDrive's scans
};

// A pairs.json transform: 4 rows of 4.
Transform TransformFromJson(const json& rows) {
  Transform T;
  for (int k = 0; k < 16; ++k) T(k / 4, k % 4) = rows[k / 4][k % 4].get<double>();
  return T;
}

// The count per rung `map` closes with, from pairs.json's answered_by:
// "31 prior, 5 features, 2 short, 1 full, 1 retry", rungs with none left out.

std::string RungLine(const json& pairs) {
  const std::pair<const char*, const char*> ladder[] = {{"prior", "prior"},
                                                        {"features", "features"},
                                                        {"short-search", "short"},
                                                        {"full-search", "full"},
                                                        {"retry", "retry"}};
  std::string line;
  for (const auto& [rung, word] : ladder) {
    const auto count = std::count_if(pairs.begin(), pairs.end(),
                                     [&](const json& p) { return p["answered_by"] == rung; });
    if (count > 0) line += (line.empty() ? "" : ", ") + std::to_string(count) + " " + word;
  }
  return line;
}

// "000002-000003.json" for a pairs.json entry.
std::string PairFileName(const json& pair) {
  char name[32];
  std::snprintf(name, sizeof(name), "%06d-%06d.json", pair["source"].get<int>(),
                pair["target"].get<int>());
  return name;
}

// Rewrites one pair file through `edit` (a JSON object in, one out).
void EditPairFile(const fs::path& file, const std::function<void(json&)>& edit) {
  json j = json::parse(Slurp(file));
  edit(j);
  std::ofstream(file, std::ios::trunc) << j.dump(1);
}

TEST_F(MapCli, DoubtfulPairsAreMarkedAndOldPairFilesStillLoad) {
  const fs::path scans = MakeDrive(4);
  const fs::path out = dir_ / "out";
  const std::string args = "map " + scans.string() + " -o " + out.string() + Quick() + " --json";
  const RunResult first = Run(args);
  ASSERT_EQ(first.exit_code, 0) << first.err;
  json pairs = json::parse(Slurp(out / "pairs.json"));
  ASSERT_EQ(pairs.size(), 3u);
  int doubtful = 0;
  for (const json& p : pairs) {
    ASSERT_TRUE(p.contains("doubtful") && p["doubtful"].is_boolean()) << p.dump();
    ASSERT_TRUE(p.contains("overlap") && p["overlap"].is_number()) << p.dump();
    ASSERT_TRUE(p.contains("search_reach") && p["search_reach"].is_number()) << p.dump();
    ASSERT_TRUE(p.contains("unconstrained") && p["unconstrained"].is_array()) << p.dump();
    EXPECT_EQ(p["doubtful"].get<bool>(), p["confidence"].get<double>() < kTrustedFrom);
    EXPECT_GT(p["overlap"].get<double>(), 0.0);
    doubtful += p["doubtful"].get<bool>();
    // Which rung answered, in pairs.json and in the pair's own file.
    ASSERT_TRUE(p.contains("answered_by") && p["answered_by"].is_string()) << p.dump();
    const json file = json::parse(Slurp(out / "pairs" / PairFileName(p)));
    EXPECT_EQ(file["answered_by"], p["answered_by"]);
    EXPECT_EQ(file["evaluations"], p["evaluations"]);
  }
  EXPECT_EQ(json::parse(first.out)["pairs_doubtful"], doubtful);
  EXPECT_THAT(first.err, HasSubstr(std::to_string(doubtful) + " of 3 pairs doubtful"));
  // A closing line counts the rungs.
  EXPECT_THAT(RungLine(pairs), ::testing::MatchesRegex("[0-9]+ [a-z]+(, [0-9]+ [a-z]+)*"));
  EXPECT_THAT(first.err, HasSubstr("\n" + RungLine(pairs) + "\n")) << first.err;

  // Files written before the marks existed (and before files had a format)
  // load as trusted, overlap and reach unknown, answered by the full search;
  // a file marked doubtful is counted as such.
  for (const char* name : {"000000-000001.json", "000001-000002.json"}) {
    EXPECT_EQ(json::parse(Slurp(out / "pairs" / name))["format"], 2);
    EditPairFile(out / "pairs" / name, [](json& j) {
      j.erase("format");
      j.erase("doubtful");
      j.erase("overlap");
      j.erase("search_reach");
      j.erase("answered_by");
    });
  }
  // A file of format 1 predates the unconstrained directions: unknown.
  EditPairFile(out / "pairs" / "000002-000003.json", [](json& j) {
    j["format"] = 1;
    j.erase("unconstrained");
    j["doubtful"] = true;
    j["confidence"] = 0.1;
  });
  const RunResult again = Run(args);
  ASSERT_EQ(again.exit_code, 0) << again.err;
  EXPECT_EQ(json::parse(again.out)["pairs_reused"], 3);
  EXPECT_EQ(json::parse(again.out)["pairs_doubtful"], 1);
  // The doubtful pair is bridged: 1 -> 3 is listed besides the chain.
  EXPECT_THAT(again.err, HasSubstr("1 of 4 pairs doubtful"));
  EXPECT_THAT(again.err, HasSubstr("(doubtful)"));
  pairs = json::parse(Slurp(out / "pairs.json"));
  EXPECT_EQ(pairs[0]["doubtful"], false);
  EXPECT_TRUE(pairs[0]["overlap"].is_null());
  EXPECT_TRUE(pairs[0]["search_reach"].is_null());
  EXPECT_EQ(pairs[0]["answered_by"], "full-search");
  EXPECT_EQ(pairs[1]["answered_by"], "full-search");
  EXPECT_EQ(pairs[2]["doubtful"], true);
  EXPECT_TRUE(pairs[2]["unconstrained"].is_null());
  EXPECT_THAT(again.err, HasSubstr("\n" + RungLine(pairs) + "\n")) << again.err;
  EXPECT_THAT(RungLine(pairs), HasSubstr("full")) << again.err;
}

// A pair file's config object as it was written before it followed the
// settings schema: three settings under other names, the retry switch the
// other way round, engine constants no front end sets, and no ICP objective
// or budget.
json OlderPairConfig(const json& config) {
  json old = config;
  const std::pair<const char*, const char*> renamed[] = {
      {"max_correspondence", "max_correspondence_distance"},
      {"icp_iterations", "icp_max_iterations"},
      {"scan_max_range", "max_range"}};
  for (const auto& [key, old_key] : renamed) {
    old[old_key] = old.at(key);
    old.erase(key);
  }
  old["retry_when_doubtful"] = !old.at("no_retry").get<bool>();
  old.erase("no_retry");
  old.erase("icp_objective");  // point-to-point was the only one
  old.erase("budget");         // the full search was the only one
  old.erase("method");         // BO-ICP was the only one
  old["finish_icp_iterations"] = 5;
  old["refine_max_iterations"] = 60;
  old["refine_candidates"] = 3;
  old["refine_source_points"] = 10000;
  old["inlier_distance"] = 1.5 * old.at("refine_voxel").get<double>();
  return old;
}

TEST_F(MapCli, PairFilesOfTheOlderSettingsFormatAreReused) {
  const fs::path scans = MakeDrive(4);
  const fs::path out = dir_ / "out";
  const std::string args = "map " + scans.string() + " -o " + out.string() + Quick() +
                           " --json --icp-objective point --budget fixed";
  const RunResult first = Run(args);
  ASSERT_EQ(first.exit_code, 0) << first.err;
  const std::string trajectory = Slurp(out / "trajectory.kitti");
  for (const char* name : {"000000-000001.json", "000001-000002.json", "000002-000003.json"}) {
    EditPairFile(out / "pairs" / name, [](json& j) {
      j.erase("format");
      j["settings"]["config"] = OlderPairConfig(j["settings"]["config"]);
    });
  }
  // One of them computed with another ICP gate: registered again.
  EditPairFile(out / "pairs" / "000002-000003.json",
               [](json& j) { j["settings"]["config"]["max_correspondence_distance"] = 0.123; });
  const RunResult again = Run(args);
  ASSERT_EQ(again.exit_code, 0) << again.err;
  EXPECT_EQ(json::parse(again.out)["pairs_reused"], 2);
  EXPECT_EQ(Slurp(out / "trajectory.kitti"), trajectory);
  const json kept = json::parse(Slurp(out / "pairs" / "000000-000001.json"));
  EXPECT_TRUE(kept["settings"]["config"].contains("retry_when_doubtful")) << "rewritten";
  const json redone = json::parse(Slurp(out / "pairs" / "000002-000003.json"));
  EXPECT_TRUE(redone["settings"]["config"].contains("no_retry")) << "not registered again";

  // A file of a format newer than this boicp reads is refused, not misread.
  EXPECT_EQ(redone["format"], 2);
  EditPairFile(out / "pairs" / "000002-000003.json", [](json& j) { j["format"] = 3; });
  const RunResult newer = Run(args);
  EXPECT_EQ(newer.exit_code, 2) << newer.err;
  EXPECT_THAT(newer.err, HasSubstr("000002-000003.json"));
  EXPECT_THAT(newer.err, HasSubstr("format 3 is newer than this boicp reads (2)"));
}

TEST_F(MapCli, GeneratedDriveWritesEveryOutputAndRerunsReusePairs) {
  const fs::path scans = MakeDrive(4);
  const fs::path out = dir_ / "out";
  const RunResult r = Run("map " + scans.string() + " -o " + out.string() + Quick() + " --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const json summary = json::parse(r.out);  // stdout holds the JSON summary only
  EXPECT_EQ(summary["scans"], 4);
  EXPECT_EQ(summary["pairs"], 3);
  EXPECT_EQ(summary["pairs_reused"], 0);
  EXPECT_EQ(summary["layout"], "files");
  ASSERT_EQ(summary["drives"].size(), 1u);
  EXPECT_EQ(summary["drives"][0]["trajectory_kitti"], "trajectory.kitti");
  EXPECT_THAT(r.err, HasSubstr("(3/3)")) << "progress goes to stderr";

  octomap::OcTree tree(0.1);
  ASSERT_TRUE(tree.readBinary((out / "map.bt").string()));
  EXPECT_DOUBLE_EQ(tree.getResolution(), 0.3);
  EXPECT_GT(tree.getNumLeafNodes(), 1000u);
  std::unique_ptr<octomap::AbstractOcTree> full(
      octomap::AbstractOcTree::read((out / "map.ot").string()));
  ASSERT_NE(dynamic_cast<octomap::OcTree*>(full.get()), nullptr);
  EXPECT_GT(DistinctColours(out / "preview.png"), 10u);

  const std::vector<TimedPose> tum = ReadTumTrajectory((out / "trajectory.tum").string());
  const std::vector<Transform> kitti = ReadKittiTrajectory((out / "trajectory.kitti").string());
  ASSERT_EQ(tum.size(), 4u);
  ASSERT_EQ(kitti.size(), 4u);
  for (size_t i = 0; i < 4; ++i) {
    const Transform expected = truth_[0].inverse() * truth_[i];
    EXPECT_NEAR(TranslationNorm(expected.inverse() * kitti[i]), 0.0, 0.1) << "scan " << i;
    EXPECT_NEAR(RotationAngle(expected.inverse() * kitti[i]), 0.0, 0.02) << "scan " << i;
  }

  const json pairs = json::parse(Slurp(out / "pairs.json"));
  ASSERT_EQ(pairs.size(), 3u);
  for (size_t i = 0; i < 3; ++i) {
    const json& p = pairs[i];
    EXPECT_EQ(p["source"], i);
    EXPECT_EQ(p["target"], i + 1);
    for (const char* key : {"source_path", "target_path", "transform", "objective", "fitness",
                            "inlier_rmse", "confidence", "evaluations", "runtime_s", "seed"}) {
      EXPECT_TRUE(p.contains(key)) << key;
    }
    EXPECT_EQ(p["transform"].size(), 4u);
    EXPECT_TRUE(
        fs::exists(out / "pairs" /
                   ("00000" + std::to_string(i) + "-00000" + std::to_string(i + 1) + ".json")));
  }

  // A kill mid-run leaves finished pair files and maybe a temporary one: the
  // rerun registers only what is missing and gives the same answer.
  const std::string trajectory = Slurp(out / "trajectory.kitti");
  fs::remove(out / "pairs" / "000001-000002.json");
  std::ofstream(out / "pairs" / "000001-000002.json.tmp") << "{\"half\": ";
  fs::remove(out / "map.bt");
  const RunResult again =
      Run("map " + scans.string() + " -o " + out.string() + Quick() + " --json");
  ASSERT_EQ(again.exit_code, 0) << again.err;
  EXPECT_EQ(json::parse(again.out)["pairs_reused"], 2);
  EXPECT_EQ(Slurp(out / "trajectory.kitti"), trajectory);
  EXPECT_TRUE(fs::exists(out / "map.bt"));

  // Other settings (another seed) redo every pair instead of reusing them.
  const RunResult other =
      Run("map " + scans.string() + " -o " + out.string() + Quick(6) + " --count 2 --json");
  ASSERT_EQ(other.exit_code, 0) << other.err;
  EXPECT_EQ(json::parse(other.out)["pairs_reused"], 0);

  // `boicp preview` draws the same kind of picture, at the size asked for.
  const RunResult preview =
      Run("preview " + (out / "map.bt").string() + " -o " + (dir_ / "p.png").string() +
          " --trajectory " + (out / "trajectory.tum").string() + " --size 300");
  ASSERT_EQ(preview.exit_code, 0) << preview.err;
  open3d::geometry::Image image;
  ASSERT_TRUE(open3d::io::ReadImage((dir_ / "p.png").string(), image));
  EXPECT_EQ(std::max(image.width_, image.height_), 300);
  EXPECT_GT(DistinctColours(dir_ / "p.png"), 10u);
}

// Returns 1-2 km out in one scan: set aside while choosing the settings,
// listed per measured scan in run.json, and the drive still maps.
TEST_F(MapCli, FarReturnsAreListedInRunJson) {
  const fs::path scans = MakeDrive(3);
  Points scan = LoadPointCloud((scans / "scan001.xyz").string()).points;
  const size_t added = scan.size() / 50;
  for (size_t i = 0; i < added; ++i) {
    const double angle = 0.1 * static_cast<double>(i), range = 1000.0 + static_cast<double>(i);
    scan.push_back(Point(range * std::cos(angle), range * std::sin(angle), 5.0));
  }
  WriteXyz((scans / "scan001.xyz").string(), scan);
  const fs::path out = dir_ / "out";
  const RunResult r = Run("map " + scans.string() + " -o " + out.string() + Quick());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_THAT(r.err, HasSubstr(std::to_string(added) + " points of 1 of the 3 measured scans"));
  const json manifest = json::parse(Slurp(out / "run.json"));
  ASSERT_EQ(manifest["far_returns"].size(), 3u);
  for (size_t i = 0; i < 3; ++i) {
    const json& entry = manifest["far_returns"][i];
    EXPECT_EQ(fs::path(entry["scan"].get<std::string>()).filename(),
              "scan00" + std::to_string(i) + ".xyz");
    EXPECT_EQ(entry["points"], i == 1 ? added : 0u) << "scan " << i;
  }
  // The sensor the settings assumed, and why: the far returns do not hide the ring.
  EXPECT_EQ(manifest["sensor_setting"], "auto");  // --sensor, not given
  EXPECT_EQ(manifest["sensor"]["type"], "lidar");
  EXPECT_THAT(manifest["sensor"]["why"].get<std::string>(), HasSubstr("ring covering 360 deg"));
  EXPECT_THAT(r.err, HasSubstr("settings: sensor lidar (ring covering 360 deg"));
  const std::vector<Transform> poses = ReadKittiTrajectory((out / "trajectory.kitti").string());
  ASSERT_EQ(poses.size(), 3u);
  for (size_t i = 0; i < 3; ++i) {
    const Transform expected = truth_[0].inverse() * truth_[i];
    EXPECT_NEAR(TranslationNorm(expected.inverse() * poses[i]), 0.0, 0.1) << "scan " << i;
  }
}

// The drive's last two scans shrunk to 1/8, as if it went indoors: the
// settings come from five scans, mostly full size, and `map` says that the
// small scans' pairs search at settings scaled to fit them.
TEST_F(MapCli, ScansAtAnotherScaleAreCounted) {
  const fs::path scans = MakeDrive(6);
  const RunResult same = Run("map " + scans.string() + " -o " + (dir_ / "same").string() + Quick());
  ASSERT_EQ(same.exit_code, 0) << same.err;
  EXPECT_THAT(same.err, Not(HasSubstr("nearer or farther")));
  for (const char* name : {"scan004.xyz", "scan005.xyz"}) {
    Points scan = LoadPointCloud((scans / name).string()).points;
    for (Point& p : scan) p /= 8.0;
    WriteXyz((scans / name).string(), scan);
  }
  const RunResult r = Run("map " + scans.string() + " -o " + (dir_ / "out").string() + Quick());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_THAT(r.err, HasSubstr("settings: 2 of 6 scans reach over 2 times nearer or farther"));
}

TEST_F(MapCli, BadInputGivesOneLineErrorExitCode2AndNoMap) {
  const fs::path scans = MakeDrive(3);
  fs::create_directories(dir_ / "mixed");
  fs::copy_file(scans / "scan000.xyz", dir_ / "mixed" / "a.xyz");
  std::ofstream(dir_ / "mixed" / "b.ply") << "ply\n";
  fs::create_directories(dir_ / "broken");
  fs::copy_file(scans / "scan000.xyz", dir_ / "broken" / "a.xyz");
  std::ofstream(dir_ / "broken" / "b.xyz") << "1 2 nonsense\n";
  std::ofstream(dir_ / "split.csv") << "source,target\n0,1\n";
  std::ofstream(dir_ / "bad.csv") << "0;1\n";
  std::ofstream(dir_ / "not_a_map.bt") << "hello\n";

  const std::string out = " -o " + (dir_ / "out").string();
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"map " + (dir_ / "none").string() + out, "none: no such folder"},
      {"map " + (dir_ / "mixed").string() + out, "mixes point formats"},
      {"map " + (dir_ / "broken").string() + out, "b.xyz"},
      {"map " + scans.string() + out + " --layout kitti", "velodyne: no .bin scans"},
      {"map " + scans.string() + out + " --layout lidar", "'lidar'"},
      {"map " + scans.string() + out + " --pairing sideways", "'sideways'"},
      {"map " + scans.string() + out + " --pairing explicit " + (dir_ / "nofile.csv").string(),
       "nofile.csv"},
      {"map " + scans.string() + out + " --pairing explicit " + (dir_ / "split.csv").string(),
       "split.csv"},
      {"map " + scans.string() + out + " --pairing explicit " + (dir_ / "bad.csv").string(),
       "bad.csv:1"},
      {"map " + scans.string() + out + " --extra-pairs " + (dir_ / "split.csv").string(),
       "split.csv: pair 2 (0->1): the same two scans are already paired"},
      {"map " + scans.string() + out + " --pairing explicit " + (dir_ / "split.csv").string() +
           " --extra-pairs " + (dir_ / "split.csv").string(),
       "--extra-pairs: explicit pairing lists every pair in its FILE"},
      {"map " + scans.string() + out + " --overlap-threshold 0.5",
       "--overlap-threshold: only overlap pairing has one"},
      {"map " + scans.string() + out + " --pairing overlap --overlap-threshold 1.5",
       "overlap_threshold must be in (0, 1]"},
      {"map " + scans.string() + out + " --count 1", "at least 2 scans"},
      {"map " + scans.string() + out + " --resolution -1", "resolution"},
      {"map " + scans.string() + out + " --config Z", "Z"},
      {"map " + scans.string() + out + " --resolution 0.01 --max-range 200 --max-fusion-mb 64",
       "over the fusion memory limit of 64 MB (--max-fusion-mb)"},
      {"map " + scans.string() + out + " --voxel 0.0000001",
       "voxel: 1e-07 m is finer than 1e-05 of the scans' extent"},
      {"map " + scans.string() + out + " --budget nope",
       "--budget: unknown budget 'nope' (expected auto or fixed)"},
      {"preview " + (dir_ / "not_a_map.bt").string() + " -o " + (dir_ / "p.png").string(),
       "not an OctoMap file"},
  };
  for (const auto& [args, message] : cases) {
    const RunResult r = Run(args);
    EXPECT_EQ(r.exit_code, 2) << args << "\n" << r.err;
    EXPECT_THAT(r.err, HasSubstr(message)) << args;
    EXPECT_THAT(r.err, HasSubstr(": error: ")) << args;
    EXPECT_EQ(CountLines(r.err), 1) << args << "\n" << r.err;
    EXPECT_TRUE(r.out.empty()) << args;
    EXPECT_FALSE(fs::exists(dir_ / "out" / "map.bt")) << args;
  }
}

TEST_F(MapCli, KittiConfigAFollowsTheReferencePosesLoosely) {
  const fs::path kitti = fs::path(BOICP_SHARED_DATA_DIR) / "kitti00";
  if (!fs::is_directory(kitti)) GTEST_SKIP() << "shared data not found at " << kitti;
  const fs::path out = dir_ / "out";
  const RunResult r = Run("map " + kitti.string() + " -o " + out.string() +
                          " --config A --count 4 --rotation-bounds 0.2,0.2,3.14159 --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(json::parse(r.out)["layout"], "kitti");
  const std::vector<Transform> poses = ReadKittiTrajectory((out / "trajectory.kitti").string());
  ASSERT_EQ(poses.size(), 4u);
  ScanFolderOptions options;
  options.count = 4;
  const ScanFolder folder = ReadScanFolder(kitti.string(), options);
  // PROVENANCE.txt: the official poses of these first frames overstate the
  // speed (0.86 against about 0.69 m a frame), so 25 % and 1.5 degrees.
  for (size_t i = 1; i < 4; ++i) {
    const Transform reference = folder.reference_poses[0]->inverse() * *folder.reference_poses[i];
    const Transform error = reference.inverse() * poses[i];
    EXPECT_LT(TranslationNorm(error), 0.25 * TranslationNorm(reference)) << "scan " << i;
    EXPECT_LT(RotationAngle(error), 1.5 * M_PI / 180) << "scan " << i;
  }
  EXPECT_GT(DistinctColours(out / "preview.png"), 10u);
}

// A depth-camera folder with no flags: the settings come from the scans.
TEST_F(MapCli, SevenScenesWithNoFlagsFollowsTheReferencePoses) {
  const fs::path scenes = fs::path(BOICP_SHARED_DATA_DIR) / "7scenes_redkitchen";
  if (!fs::is_directory(scenes)) GTEST_SKIP() << "shared data not found at " << scenes;
  const fs::path out = dir_ / "out";
  const RunResult r =
      Run("map " + scenes.string() + " -o " + out.string() + " --stride 10 --count 6 --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(json::parse(r.out)["layout"], "7scenes");
  std::ifstream manifest_file(out / "run.json");
  const json manifest = json::parse(manifest_file);
  // A room, not a street: centimetre voxels and map cells.
  EXPECT_LT(manifest["chosen"]["voxel"].get<double>(), 0.1);
  EXPECT_LT(manifest["chosen"]["map_resolution"].get<double>(), 0.05);
  EXPECT_EQ(manifest["chosen"]["rotation_bounds"], json({M_PI, M_PI / 2, M_PI}));
  EXPECT_THAT(manifest["auto"], ::testing::Contains("voxel"));
  const std::vector<Transform> poses = ReadKittiTrajectory((out / "trajectory.kitti").string());
  ASSERT_EQ(poses.size(), 6u);
  ScanFolderOptions options;
  options.stride = 10;
  options.count = 6;
  const ScanFolder folder = ReadScanFolder(scenes.string(), options);
  for (size_t i = 1; i < 6; ++i) {
    const Transform reference =
        folder.reference_poses[i - 1]->inverse() * *folder.reference_poses[i];
    const Transform error = reference.inverse() * (poses[i - 1].inverse() * poses[i]);
    std::fprintf(stderr, "7-Scenes pair %zu->%zu: %.3f m, %.2f deg from the reference\n", i - 1, i,
                 TranslationNorm(error), RotationAngle(error) * 180 / M_PI);
    EXPECT_LT(TranslationNorm(error), 0.05) << "pair " << i - 1 << "->" << i;
    EXPECT_LT(RotationAngle(error), 2.0 * M_PI / 180) << "pair " << i - 1 << "->" << i;
  }
  // A picture with structure in it, not a handful of blocks.
  EXPECT_GT(DistinctColours(out / "preview.png"), 50u);
}

// `eval` against a trajectory file with one pose per scan, and against a
// revisits CSV, on a generated drive whose truth is known.
TEST_F(MapCli, EvalScoresTheTrajectoryAndRevisits) {
  const fs::path scans = MakeDrive(6);
  const fs::path out = dir_ / "out";
  ASSERT_EQ(Run("map " + scans.string() + " -o " + out.string() + Quick()).exit_code, 0);
  const fs::path truth = dir_ / "truth.kitti";
  {
    std::ofstream file(truth);
    WriteKittiTrajectory(file, truth_);
  }
  const RunResult r = Run("eval " + out.string() + " --reference " + truth.string() + " --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const json result = json::parse(r.out);
  EXPECT_EQ(result["trajectory"]["scans"], 6);
  EXPECT_LT(result["trajectory"]["ate_rmse_m"].get<double>(), 0.05);
  EXPECT_EQ(result["pair_errors"]["by_kind"]["chain"]["pairs"], 5);
  EXPECT_EQ(result["pair_errors"]["by_kind"]["chain"]["wrong_trusted"], 0);
  EXPECT_THAT(Run("eval " + out.string() + " --reference " + truth.string()).out,
              HasSubstr("0 wrong and trusted"));

  // Scan 4 seen from scan 0, as the truth has it, and once 1 m off.
  const Transform relative = truth_[0].inverse() * truth_[4];
  const double yaw = std::atan2(relative(1, 0), relative(0, 0)) * 180 / M_PI;
  const fs::path revisits = dir_ / "revisits.csv";
  std::ofstream(revisits)
      << "earlier,later,inlier_share_0.3m,rms_m,tx_m,ty_m,tz_m,yaw_deg,verdict\n"
      << "scan000.xyz,scan004.xyz,0.5,0.1," << relative(0, 3) << "," << relative(1, 3) << ","
      << relative(2, 3) << "," << yaw << ",revisit\n"
      << "scan001.xyz,scan005.xyz,0.5,0.1,9,0,0,0,revisit\n"
      << "scan001.xyz,scan004.xyz,0.1,0.9,0,0,0,0,unconfirmed\n";
  const RunResult scored = Run("eval " + out.string() + " --reference " + revisits.string());
  ASSERT_EQ(scored.exit_code, 0) << scored.err;
  EXPECT_THAT(scored.out, HasSubstr("revisits: 1 of 2 within 0.3 m and 2 deg"));

  const RunResult missing =
      Run("eval " + (dir_ / "nothing").string() + " --reference " + truth.string());
  EXPECT_EQ(missing.exit_code, 2);
  EXPECT_THAT(missing.err, HasSubstr("trajectory.kitti"));
}

// A real depth drive that comes back over itself: the map finds its loops,
// verifies them, and they bring the trajectory closer to the reference.
// 7-Scenes frames 0-495 every 5th (100 scans), reference poses from
// KinectFusion.
TEST_F(MapCli, SevenScenesDriveClosesItsOwnLoops) {
  const fs::path scenes = fs::path(BOICP_SHARED_DATA_DIR) / "7scenes_redkitchen";
  if (!fs::is_directory(scenes)) GTEST_SKIP() << "shared data not found at " << scenes;
  const fs::path drive = dir_ / "7scenes_every_5th";
  fs::create_directories(drive / "depth");
  fs::create_directories(drive / "pose");
  fs::copy_file(scenes / "camera-intrinsics.txt", drive / "camera-intrinsics.txt");
  for (int frame = 0; frame < 500; frame += 5) {
    char name[32];
    std::snprintf(name, sizeof(name), "frame-%06d", frame);
    fs::create_symlink(scenes / "depth" / (std::string(name) + ".depth.png"),
                       drive / "depth" / (std::string(name) + ".depth.png"));
    fs::create_symlink(scenes / "pose" / (std::string(name) + ".pose.txt"),
                       drive / "pose" / (std::string(name) + ".pose.txt"));
  }
  const auto ate = [&](const fs::path& out) {
    const RunResult r = Run("eval " + out.string() + " --reference " + drive.string() + " --json");
    EXPECT_EQ(r.exit_code, 0) << r.err;
    return json::parse(r.out)["trajectory"]["ate_rmse_m"].get<double>();
  };
  // The looped run reuses the chain run's pair files and registers only its
  // loops, as a user's second run would.
  const fs::path looped = dir_ / "looped";
  const RunResult chain = Run("map " + drive.string() + " -o " + looped.string() + " --loops off");
  ASSERT_EQ(chain.exit_code, 0) << chain.err;
  const double without = ate(looped);
  const RunResult r = Run("map " + drive.string() + " -o " + looped.string() + " --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const json summary = json::parse(r.out);
  EXPECT_GE(summary["pairs_reused"].get<int>(), 99) << "every chain pair";
  EXPECT_GT(summary["loops_closed"].get<int>(), 3);
  EXPECT_LE(summary["loops_closed"].get<int>(), summary["loop_candidates"].get<int>());
  EXPECT_THAT(r.err, ::testing::ContainsRegex("[0-9]+ loops closed of [0-9]+ candidates"));
  const json pairs = json::parse(Slurp(looped / "pairs.json"));
  int loops = 0;
  for (const json& pair : pairs) {
    if (pair["kind"] != "loop") continue;
    ++loops;
    EXPECT_EQ(pair["found_by"], "poses");
    EXPECT_EQ(pair["in_graph"].get<bool>(), pair["left_out_because"].get<std::string>().empty());
  }
  EXPECT_EQ(loops, summary["loop_candidates"].get<int>());
  const double with = ate(looped);
  std::fprintf(stderr, "7-Scenes every 5th frame: ATE %.3f m without loops, %.3f m with\n", without,
               with);
  EXPECT_LT(with, 0.8 * without);
}

// A real VLP-16 drive that comes back to its start after a gap no
// registration bridges (scans 9-21, then 385-386 of ../shared/data/vlp16_loop):
// the chain puts the return tens of metres off; place recognition finds the
// return whatever the chain says, registration trusts it, and the map's
// revisits agree with revisits.csv.
TEST_F(MapCli, AVlp16ReturnIsFoundByItsPlace) {
  const fs::path data = fs::path(BOICP_SHARED_DATA_DIR) / "vlp16_loop";
  if (!fs::is_directory(data)) GTEST_SKIP() << "shared data not found at " << data;
  const fs::path drive = dir_ / "vlp16_return";
  fs::create_directories(drive);
  std::vector<int> frames = {385, 386};
  for (int frame = 9; frame <= 21; ++frame) frames.push_back(frame);
  for (const int frame : frames) {
    char name[32];
    std::snprintf(name, sizeof(name), "%06d.pcd", frame);
    fs::create_symlink(data / "pcd" / name, drive / name);
  }
  const auto revisits = [&](const fs::path& out) {
    const RunResult r =
        Run("eval " + out.string() + " --reference " + (data / "revisits.csv").string());
    EXPECT_EQ(r.exit_code, 0) << r.err;
    return r.out;
  };
  // The looped run reuses the chain run's pairs.
  const fs::path looped = dir_ / "looped";
  ASSERT_EQ(Run("map " + drive.string() + " -o " + looped.string() + " --loops off").exit_code, 0);
  EXPECT_THAT(revisits(looped), HasSubstr("revisits: 0 of 2 within"));

  const RunResult r = Run("map " + drive.string() + " -o " + looped.string() + " --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_THAT(revisits(looped), HasSubstr("revisits: 2 of 2 within 0.3 m and 2 deg"));
  int closed_by_place = 0;
  for (const json& pair : json::parse(Slurp(looped / "pairs.json"))) {
    if (pair["kind"] == "loop" && pair["found_by"] == "place" && pair["in_graph"].get<bool>()) {
      ++closed_by_place;
    }
  }
  EXPECT_GE(closed_by_place, 1);
}

// Two drives of one street, in two folders, each scan in its own sensor
// frame: each drive is chained, place recognition joins the second to the
// first with no prior between them, and each drive's trajectory is written
// in the first drive's frame.
TEST_F(MapCli, TwoDrivesOfOneStreetMakeOneMap) {
  const fs::path first = MakeDrive(8), second = SplitDrive(first, 4, "second");
  const fs::path out = dir_ / "out";
  const RunResult r = Run("map " + first.string() + " " + second.string() + " -o " + out.string() +
                          Quick() + " --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const json summary = json::parse(r.out);
  ASSERT_EQ(summary["drives"].size(), 2u);
  EXPECT_EQ(summary["drives"][1]["first_scan"], 4);
  EXPECT_EQ(summary["drives"][1]["scans"], 4);
  EXPECT_EQ(summary["drives"][1]["trajectory_kitti"], "trajectory-second.kitti");
  EXPECT_EQ(summary["outputs"]["trajectory-second.kitti"],
            (out / "trajectory-second.kitti").string());

  int joining = 0;
  for (const json& pair : json::parse(Slurp(out / "pairs.json"))) {
    const int source = pair["source"].get<int>(), target = pair["target"].get<int>();
    EXPECT_FALSE(pair["kind"] == "chain" && (source < 4) != (target < 4))
        << "no chain pair joins the drives";
    if ((source < 4) != (target < 4) && pair["in_graph"].get<bool>()) {
      ++joining;
      EXPECT_EQ(pair["found_by"], "place");
    }
  }
  EXPECT_GE(joining, 1);

  const std::vector<Transform> drive_one =
      ReadKittiTrajectory((out / "trajectory-drive.kitti").string());
  const std::vector<Transform> drive_two =
      ReadKittiTrajectory((out / "trajectory-second.kitti").string());
  ASSERT_EQ(drive_one.size(), 4u);
  ASSERT_EQ(drive_two.size(), 4u);
  for (size_t i = 0; i < 4; ++i) {
    const Transform truth = truth_[0].inverse() * truth_[4 + i];
    EXPECT_LT(TranslationNorm(truth.inverse() * drive_two[i]), 0.1) << "second drive, scan " << i;
    EXPECT_LT(RotationAngle(truth.inverse() * drive_two[i]), 0.02) << "second drive, scan " << i;
  }
}

// A second drive of another street: no trusted pair joins it to the first,
// and the map names it instead of placing it anywhere.
TEST_F(MapCli, ADriveThatOverlapsNoOtherIsNamed) {
  const fs::path first = MakeDrive(4), elsewhere = dir_ / "elsewhere";
  fs::create_directories(elsewhere);
  const Points other_street = MakeStreetSegment(29, 2);  // x from 120 to 200 m
  for (int i = 0; i < 3; ++i) {
    const Transform pose = PoseFromYawTranslation(1.2 + 0.04 * i, {155.0 + 2.0 * i, 0.5, 1.8});
    char name[32];
    std::snprintf(name, sizeof(name), "other%03d.xyz", i);
    WriteXyz((elsewhere / name).string(), SimulateScan(other_street, pose, 30.0, 0.02, 300 + i));
  }
  const RunResult r = Run("map " + first.string() + " " + elsewhere.string() + " -o " +
                          (dir_ / "out").string() + Quick());
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_THAT(r.err, HasSubstr("drive 2 (from " + (elsewhere / "other000.xyz").string() +
                               "): overlaps no other drive"));
  EXPECT_FALSE(fs::exists(dir_ / "out" / "trajectory.kitti"));
  EXPECT_TRUE(fs::exists(dir_ / "out" / "pairs" / "000004-000005.json"))
      << "pairs kept for a rerun";
  int registered = 0;
  for (const auto& file : fs::directory_iterator(dir_ / "out" / "pairs"))
    registered += file.is_regular_file();
  EXPECT_GT(registered, 5) << "besides the 5 chain pairs, a place candidate joining the drives";

  const RunResult single = Run("map " + first.string() + " " + (dir_ / "none").string() + " -o " +
                               (dir_ / "out2").string() + Quick());
  EXPECT_EQ(single.exit_code, 2);
  EXPECT_THAT(single.err, HasSubstr((dir_ / "none").string()));
}

// The same return as two drives in two folders (scans 9-21; 385-386): no
// chain pair joins them, place recognition does, and the revisits across
// them agree with revisits.csv.
TEST_F(MapCli, TwoVlp16DrivesJoinWhereTheyRevisit) {
  const fs::path data = fs::path(BOICP_SHARED_DATA_DIR) / "vlp16_loop";
  if (!fs::is_directory(data)) GTEST_SKIP() << "shared data not found at " << data;
  const fs::path first = dir_ / "first", second = dir_ / "second";
  fs::create_directories(first);
  fs::create_directories(second);
  for (int frame = 9; frame <= 21; ++frame) {
    char name[32];
    std::snprintf(name, sizeof(name), "%06d.pcd", frame);
    fs::create_symlink(data / "pcd" / name, first / name);
  }
  for (const char* name : {"000385.pcd", "000386.pcd"}) {
    fs::create_symlink(data / "pcd" / name, second / name);
  }
  const fs::path out = dir_ / "out";
  const RunResult r = Run("map " + first.string() + " " + second.string() + " -o " + out.string());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const RunResult scored =
      Run("eval " + out.string() + " --reference " + (data / "revisits.csv").string());
  EXPECT_THAT(scored.out, HasSubstr("revisits: 2 of 2 within 0.3 m and 2 deg"));
  EXPECT_EQ(ReadKittiTrajectory((out / "trajectory-second.kitti").string()).size(), 2u);
}

// Two real VLP-16 scans 3 m apart (000099, 000100 of ../shared/data/vlp16_loop):
// registered in the drive's direction the answer stays doubtful, but the
// later scan explains more of the earlier than the earlier of it. The pair
// registered the other way round is trusted, agrees with the first, and
// bridges the chain: no scan is left without a trusted pair.
TEST_F(MapCli, ADoubtfulPairIsBridgedByItselfTheOtherWayRound) {
  const fs::path data = fs::path(BOICP_SHARED_DATA_DIR) / "vlp16_loop";
  if (!fs::is_directory(data)) GTEST_SKIP() << "shared data not found at " << data;
  const fs::path drive = dir_ / "vlp16_pair";
  fs::create_directories(drive);
  for (const char* name : {"000099.pcd", "000100.pcd"}) {
    fs::create_symlink(data / "pcd" / name, drive / name);
  }
  const fs::path out = dir_ / "out";
  const RunResult r = Run("map " + drive.string() + " -o " + out.string() + " --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(json::parse(r.out)["untrusted_scans"], json::array());
  EXPECT_THAT(r.err, HasSubstr("1 of 1 doubtful chain pairs bridged by a trusted pair over them"));
  std::map<std::string, json> pairs;
  for (const json& pair : json::parse(Slurp(out / "pairs.json"))) {
    pairs[std::to_string(pair["source"].get<int>()) + "->" +
          std::to_string(pair["target"].get<int>())] = pair;
  }
  ASSERT_EQ(pairs.count("0->1"), 1u);
  ASSERT_EQ(pairs.count("1->0"), 1u) << "the chain pair the other way round";
  EXPECT_TRUE(pairs["0->1"]["doubtful"].get<bool>());
  EXPECT_EQ(pairs["1->0"]["kind"], "bridge");
  EXPECT_FALSE(pairs["1->0"]["doubtful"].get<bool>());
  EXPECT_TRUE(pairs["1->0"]["in_graph"].get<bool>());
  const Transform forward = TransformFromJson(pairs["0->1"]["transform"]);
  const Transform backward = TransformFromJson(pairs["1->0"]["transform"]);
  const double cycle = (forward * backward).topRightCorner<3, 1>().norm();
  EXPECT_LT(cycle, 0.2) << "both directions find one answer";
}

// A drive whose scan 3 is noise: neither of its pairs can be trusted. The
// bridge 2 -> 4 holds the chain together; scan 3 is named, kept in the
// trajectory, and fused only with --untrusted-scans place.
TEST_F(MapCli, ADoubtfulScanIsBridgedNamedAndLeftOut) {
  const fs::path scans = MakeDriveWithNoiseAt3();

  const fs::path out = dir_ / "out";
  const RunResult r = Run("map " + scans.string() + " -o " + out.string() + Quick() + " --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const json summary = json::parse(r.out);
  EXPECT_EQ(summary["untrusted_scans"], json::array({"scan003.xyz"}));
  EXPECT_THAT(r.err, HasSubstr("1 scan has no trusted pair; left out of the map "
                               "(--untrusted-scans place fuses them): scan003.xyz"));
  EXPECT_THAT(r.err, HasSubstr("2 of 2 doubtful chain pairs bridged by a trusted pair over them"));
  EXPECT_THAT(r.err, HasSubstr("done (7/7)")) << "the bridges are counted on from the chain's 5";

  std::map<std::string, json> bridges;
  for (const json& pair : json::parse(Slurp(out / "pairs.json"))) {
    if (pair["kind"] == "bridge") {
      bridges[std::to_string(pair["source"].get<int>()) + "->" +
              std::to_string(pair["target"].get<int>())] = pair;
    }
  }
  for (const char* reversed : {"3->2", "4->3"}) {
    ASSERT_EQ(bridges.count(reversed), 1u) << "each doubtful pair the other way round, first";
    EXPECT_TRUE(bridges[reversed]["doubtful"].get<bool>()) << reversed;
  }
  ASSERT_EQ(bridges.count("2->4"), 1u) << "the bridge one scan on from the first doubtful pair";
  EXPECT_FALSE(bridges["2->4"]["doubtful"].get<bool>());
  EXPECT_TRUE(bridges["2->4"]["in_graph"].get<bool>());
  ASSERT_EQ(bridges.count("1->3"), 1u) << "the bridge one scan back, onto the noise";
  EXPECT_THAT(bridges["1->3"]["left_out_because"].get<std::string>(),
              HasSubstr("not trusted as a bridge"));

  // Every scan keeps a pose; those after the noise follow the truth.
  const std::vector<Transform> poses = ReadKittiTrajectory((out / "trajectory.kitti").string());
  ASSERT_EQ(poses.size(), 6u);
  for (const int i : {4, 5}) {
    const Transform truth = truth_[0].inverse() * truth_[static_cast<size_t>(i)];
    EXPECT_LT((poses[static_cast<size_t>(i)].topRightCorner<3, 1>() - truth.topRightCorner<3, 1>())
                  .norm(),
              0.2)
        << "scan " << i;
  }

  // Placed, the noise adds its cells to the map; the pairs are the same.
  const RunResult p = Run("map " + scans.string() + " -o " + out.string() + Quick() +
                          " --untrusted-scans place --json");
  ASSERT_EQ(p.exit_code, 0) << p.err;
  EXPECT_EQ(json::parse(p.out)["pairs_reused"], 9) << "5 chain pairs and 4 bridges";
  EXPECT_THAT(p.err, HasSubstr("1 scan has no trusted pair; placed by the best doubtful pair: "
                               "scan003.xyz"));
  EXPECT_GT(json::parse(p.out)["occupied_leaves"].get<int>(),
            summary["occupied_leaves"].get<int>());
}

#ifdef BOICP_TEST_WITH_DAEMON
namespace v1 = ::boicp::v1;

// One pairing as `boicp map` and the daemon spell it.
struct PairingCase {
  std::string name;
  std::string cli_flags;  // after --pairing
  v1::PairingPolicy pairing;
};

// The daemon path (upload + submit, same seed, config and pairing) gives the
// same pairs and trajectory as `boicp map` for each pairing: both run core's
// map pipeline, which decides the pairs and assembles the poses, and the
// daemon's two workers against the map's one thread also show that the
// result does not depend on the thread count.
TEST_F(MapCli, SameTrajectoryAsTheDaemonForEveryPairing) {
  const fs::path scans = MakeDrive(6);
  // Explicit: the chain plus one loop closure, so the pose graph is optimised.
  const fs::path pairs_file = dir_ / "pairs.csv";
  std::ofstream(pairs_file) << "source,target\n0,1\n1,2\n2,3\n3,4\n4,5\n4,2\n";
  // The other modes take loop closures besides their own pairs, and overlap
  // pairing a threshold, in both front ends.
  const fs::path closure_file = dir_ / "closure.csv";
  std::ofstream(closure_file) << "5,1\n";
  const auto add_pair = [](v1::PairingPolicy& pairing, int source, int target) {
    v1::Pair* pair = pairing.add_pairs();
    pair->set_source(static_cast<uint32_t>(source));
    pair->set_target(static_cast<uint32_t>(target));
  };
  std::vector<PairingCase> cases(5);
  cases[0].name = "consecutive";
  cases[0].cli_flags = "consecutive";
  cases[0].pairing.set_mode(v1::PairingPolicy::MODE_CONSECUTIVE);
  cases[1].name = "overlap";
  cases[1].cli_flags = "overlap";
  cases[1].pairing.set_mode(v1::PairingPolicy::MODE_OVERLAP);
  cases[2].name = "explicit";
  cases[2].cli_flags = "explicit " + pairs_file.string();
  cases[2].pairing.set_mode(v1::PairingPolicy::MODE_EXPLICIT);
  for (const auto& [source, target] :
       std::vector<std::pair<int, int>>{{0, 1}, {1, 2}, {2, 3}, {3, 4}, {4, 5}, {4, 2}}) {
    add_pair(cases[2].pairing, source, target);
  }
  cases[3].name = "consecutive-with-a-closure";
  cases[3].cli_flags = "consecutive --extra-pairs " + closure_file.string();
  cases[3].pairing.set_mode(v1::PairingPolicy::MODE_CONSECUTIVE);
  add_pair(cases[3].pairing, 5, 1);
  cases[4].name = "overlap-at-0.8-with-a-closure";
  cases[4].cli_flags = "overlap --overlap-threshold 0.8 --extra-pairs " + closure_file.string();
  cases[4].pairing.set_mode(v1::PairingPolicy::MODE_OVERLAP);
  cases[4].pairing.set_overlap_threshold(0.8);
  add_pair(cases[4].pairing, 5, 1);

  test::DaemonProcess daemon(
      {"--data-dir", (dir_ / "daemon").string(), "--workers", "2", "--registration-threads", "1"},
      (dir_ / "daemon.log").string());
  rpc::MapBuilderClient client(rpc::Connect({daemon.address(), "", "", "", "", 4 << 20}));
  v1::SubmitBatchRequest request;
  for (size_t i = 0; i < truth_.size(); ++i) {
    char name[32];
    std::snprintf(name, sizeof(name), "scan%03zu.xyz", i);
    v1::ScanMetadata metadata;
    metadata.set_format(v1::SCAN_FORMAT_XYZ);
    request.add_scan_ids(client.UploadFile((scans / name).string(), metadata).scan_id());
  }
  v1::RegistrationConfig& config = *request.mutable_config();
  config.set_preset("A");
  config.set_random_samples(4);
  config.set_iterations(4);
  config.set_seed(5);
  config.mutable_rotation_bounds()->set_x(0.2);
  config.mutable_rotation_bounds()->set_y(0.2);
  config.mutable_rotation_bounds()->set_z(3.14159);
  request.mutable_map()->set_resolution(0.3);

  for (const PairingCase& pairing : cases) {
    SCOPED_TRACE(pairing.name);
    const fs::path out = dir_ / ("out-" + pairing.name);
    const RunResult r = Run("map " + scans.string() + " -o " + out.string() + Quick() +
                            " --pairing " + pairing.cli_flags);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    if (pairing.name == "overlap") {
      // Probes run ahead on more threads, yet the keyframes are the same.
      const fs::path wide = dir_ / "out-overlap-3-threads";
      const RunResult r3 = Run("map " + scans.string() + " -o " + wide.string() + Quick() +
                               " --pairing overlap --threads 3");
      ASSERT_EQ(r3.exit_code, 0) << r3.err;
      EXPECT_EQ(Slurp(wide / "trajectory.kitti"), Slurp(out / "trajectory.kitti"));
    }

    *request.mutable_pairing() = pairing.pairing;
    const v1::Job job = client.Watch(client.Submit(request).job_id());
    ASSERT_EQ(job.state(), v1::JOB_STATE_SUCCEEDED) << job.error() << "\n" << daemon.Log();
    const v1::JobResults results = client.Results(job.job_id());

    // Every pair both registered has the same seed and transform; the pairs
    // the poses use are the same ones.
    std::map<std::pair<int, int>, json> local_pairs;
    std::set<std::pair<int, int>> local_in_graph, remote_in_graph;
    for (const json& p : json::parse(Slurp(out / "pairs.json"))) {
      const std::pair<int, int> key{p["source"].get<int>(), p["target"].get<int>()};
      local_pairs[key] = p;
      if (p["in_graph"].get<bool>()) local_in_graph.insert(key);
    }
    for (const v1::PairResult& remote : results.pairs()) {
      const std::pair<int, int> key{static_cast<int>(remote.source()),
                                    static_cast<int>(remote.target())};
      if (remote.in_graph()) remote_in_graph.insert(key);
      const auto local = local_pairs.find(key);
      if (local == local_pairs.end()) continue;  // a keyframe probe only one side ran ahead to
      EXPECT_EQ(local->second["seed"].get<uint64_t>(), remote.seed());
      EXPECT_EQ(local->second["answered_by"], remote.answered_by());
      EXPECT_EQ(local->second["left_out_because"], remote.left_out_because());
      EXPECT_EQ(local->second["evaluations"], remote.evaluations());
      for (int k = 0; k < 16; ++k) {
        EXPECT_NEAR(local->second["transform"][k / 4][k % 4].get<double>(), remote.transform().m(k),
                    1e-12)
            << "pair " << key.first << "->" << key.second << " element " << k;
      }
    }
    EXPECT_EQ(local_in_graph, remote_in_graph);
    EXPECT_GE(local_in_graph.size(), truth_.size() - 1);
    if (pairing.name.find("closure") != std::string::npos) {
      EXPECT_EQ(local_pairs.count({5, 1}), 1u) << "the loop closure was registered";
    }
    if (pairing.name == "overlap") {
      // The street overlaps well from any distance, but the scans soon lie
      // past half of keyframe 0's search box: a later keyframe takes over.
      EXPECT_TRUE(std::any_of(local_in_graph.begin(), local_in_graph.end(),
                              [](const auto& pair) { return pair.second > 0; }));
    }

    const std::vector<Transform> local = ReadKittiTrajectory((out / "trajectory.kitti").string());
    ASSERT_EQ(local.size(), truth_.size());
    for (size_t i = 0; i < truth_.size(); ++i) {  // and both are right
      const Transform error = (truth_[0].inverse() * truth_[i]).inverse() * local[i];
      EXPECT_LT(TranslationNorm(error), 0.1) << "scan " << i;
      EXPECT_LT(RotationAngle(error), 0.02) << "scan " << i;
    }
    ASSERT_EQ(results.trajectory_size(), static_cast<int>(truth_.size()));
    for (const v1::TrajectoryPose& pose : results.trajectory()) {
      for (int k = 0; k < 12; ++k) {  // the KITTI file keeps 12 significant digits
        EXPECT_NEAR(local.at(pose.index())(k / 4, k % 4), pose.pose().m(k), 1e-9)
            << "scan " << pose.index() << " element " << k;
      }
    }
  }
}

// The daemon maps two drives as `boicp map` does: `submit A B` sends them as
// one batch with its drive start, and `export --drive 2` gives the second
// drive's trajectory as map's trajectory-NAME file.
TEST_F(MapCli, TwoDrivesGiveTheDaemonTheMapsTrajectories) {
  const fs::path first = MakeDrive(8), second = SplitDrive(first, 4, "second");
  const fs::path out = dir_ / "out";
  const std::string drives = " " + first.string() + " " + second.string() + Quick();
  const RunResult mapped = Run("map" + drives + " -o " + out.string() + " --json");
  ASSERT_EQ(mapped.exit_code, 0) << mapped.err;
  const json map_summary = json::parse(mapped.out);

  test::DaemonProcess daemon({"--data-dir", (dir_ / "daemon").string(), "--workers", "2"},
                             (dir_ / "daemon.log").string());
  const std::string server = " --server " + daemon.address();
  const RunResult submitted = Run("submit" + drives + " --wait" + server);
  ASSERT_EQ(submitted.exit_code, 0) << submitted.err << daemon.Log();
  const std::string job = submitted.out.substr(0, submitted.out.find('\n'));
  const json shown = json::parse(Run("show " + job + " --json" + server).out);
  EXPECT_EQ(shown["drives"], 2);
  ASSERT_GT(map_summary["loop_candidates"].get<int>(), 0) << "the place pairs between the drives";
  EXPECT_EQ(shown["loop_candidates"], map_summary["loop_candidates"]);
  EXPECT_EQ(shown["loops_closed"], map_summary["loops_closed"]);
  EXPECT_THAT(submitted.err, HasSubstr(LoopsClosedText(map_summary["loops_closed"].get<int>(),
                                                       map_summary["loop_candidates"].get<int>())));

  const fs::path exported = dir_ / "second.kitti";
  const RunResult r =
      Run("export " + job + " --format kitti --drive 2 -o " + exported.string() + server);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const std::vector<Transform> remote = ReadKittiTrajectory(exported.string());
  const std::vector<Transform> local =
      ReadKittiTrajectory((out / "trajectory-second.kitti").string());
  ASSERT_EQ(remote.size(), 4u);
  ASSERT_EQ(local.size(), 4u);
  for (size_t i = 0; i < 4; ++i) EXPECT_TRUE(remote[i].isApprox(local[i], 1e-9)) << "scan " << i;

  const RunResult third = Run("export " + job + " --format kitti --drive 3" + server);
  EXPECT_EQ(third.exit_code, 2) << third.err;
  EXPECT_THAT(third.err, HasSubstr("has 2 drives, not 3"));
  EXPECT_EQ(Run("export " + job + " --format bt --drive 1" + server).exit_code, 2);

  // A job of one drive: its drive 1 is all of it.
  const RunResult one = Run("submit " + first.string() + Quick() + " --wait" + server);
  ASSERT_EQ(one.exit_code, 0) << one.err;
  const std::string single = one.out.substr(0, one.out.find('\n'));
  const fs::path whole = dir_ / "whole.kitti";
  ASSERT_EQ(Run("export " + single + " --format kitti -o " + whole.string() + server).exit_code, 0);
  const RunResult drive_one = Run("export " + single + " --format kitti --drive 1 -o " +
                                  (dir_ / "one.kitti").string() + server);
  ASSERT_EQ(drive_one.exit_code, 0) << drive_one.err;
  EXPECT_EQ(Slurp(dir_ / "one.kitti"), Slurp(whole));
}

// The daemon names a scan without a trusted pair as `map` does: in the job
// (by index), in the outcome `submit --wait` prints, and in `show`.
TEST_F(MapCli, TheDaemonNamesAScanWithoutATrustedPair) {
  const fs::path scans = MakeDriveWithNoiseAt3();
  test::DaemonProcess daemon({"--data-dir", (dir_ / "daemon").string(), "--workers", "2"},
                             (dir_ / "daemon.log").string());
  const std::string server = " --server " + daemon.address();
  const RunResult submitted = Run("submit " + scans.string() + Quick() + " --wait" + server);
  ASSERT_EQ(submitted.exit_code, 0) << submitted.err << daemon.Log();
  EXPECT_THAT(submitted.err, HasSubstr("1 scan has no trusted pair; left out of the map "
                                       "(--untrusted-scans place fuses them): #3"));
  const std::string job = submitted.out.substr(0, submitted.out.find('\n'));
  const json shown = json::parse(Run("show " + job + " --json" + server).out);
  EXPECT_EQ(shown["untrusted_scans"], json::array({3}));
  EXPECT_EQ(shown["untrusted_left_out"], true);
  const std::string scan_id = shown["trajectory"][3]["scan_id"].get<std::string>();
  EXPECT_THAT(Run("show " + job + server).out,
              HasSubstr("map         1 scan has no trusted pair; left out of the map "
                        "(--untrusted-scans place fuses them): " +
                        scan_id));
}
#endif

}  // namespace
}  // namespace boicp
