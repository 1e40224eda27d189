// Sharded map runs as scripts drive them: `boicp map --shard K/N` in
// separate processes, then `boicp merge`, must equal one `boicp map` run;
// a shard rerun after a kill redoes only its missing pairs; merge refuses
// missing pairs and mismatched settings with one line and exit code 2.

#include <sys/wait.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "../support/files_and_processes.hpp"
#include "boicp/io/point_cloud_io.hpp"
#include "boicp/io/synthetic_scene.hpp"

#ifndef BOICP_SHARED_DATA_DIR
#define BOICP_SHARED_DATA_DIR ""
#endif

namespace boicp {
namespace {
using boicp::test::RunResult;
using boicp::test::Slurp;

using ::testing::HasSubstr;
namespace fs = std::filesystem;
using nlohmann::json;

class ShardCli : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("boicp_shard_cli_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  std::string Command(const std::string& args, const std::string& tag) const {
    return std::string(BOICP_CLI_PATH) + " " + args + " >" + (dir_ / (tag + ".out")).string() +
           " 2>" + (dir_ / (tag + ".err")).string();
  }
  RunResult Result(const std::string& tag, int status) const {
    return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, Slurp(dir_ / (tag + ".out")),
            Slurp(dir_ / (tag + ".err"))};
  }
  RunResult Run(const std::string& args) {
    return Result("run", std::system(Command(args, "run").c_str()));
  }

  // Runs `boicp map ... --shard K/N` for every K as concurrent processes.
  std::vector<RunResult> RunShards(const std::string& args, int n) {
    std::string script;
    for (int k = 1; k <= n; ++k) {
      const std::string tag = "shard" + std::to_string(k);
      script += "(" +
                Command(args + " --shard " + std::to_string(k) + "/" + std::to_string(n), tag) +
                "; echo $? >" + (dir_ / (tag + ".rc")).string() + ") & ";
    }
    EXPECT_EQ(std::system((script + "wait").c_str()), 0);
    std::vector<RunResult> results;
    for (int k = 1; k <= n; ++k) {
      const std::string tag = "shard" + std::to_string(k);
      RunResult r{-1, Slurp(dir_ / (tag + ".out")), Slurp(dir_ / (tag + ".err"))};
      std::ifstream(dir_ / (tag + ".rc")) >> r.exit_code;
      results.push_back(r);
    }
    return results;
  }

  // Five generated .xyz scans, 2 m apart: four consecutive pairs.
  fs::path MakeDrive() {
    const fs::path scans = dir_ / "drive";
    fs::create_directories(scans);
    const Points world = MakeSyntheticStreet(11);
    for (int i = 0; i < 5; ++i) {
      char name[32];
      std::snprintf(name, sizeof(name), "scan%03d.xyz", i);
      WriteXyz((scans / name).string(),
               SimulateScan(world, PoseFromYawTranslation(0.04 * i, {-5.0 + 2.0 * i, 0.3 * i, 1.8}),
                            30.0, 0.02, 100 + i));
    }
    return scans;
  }

  fs::path dir_;
};

std::string Quick(int seed = 5) {
  return " --config A --random-samples 4 --iterations 4 --rotation-bounds 0.2,0.2,3.14159"
         " --resolution 0.3 --seed " +
         std::to_string(seed);
}

TEST_F(ShardCli, ThreeShardsThenMergeEqualOneMapRunAndAKilledShardResumes) {
  const fs::path kitti = fs::path(BOICP_SHARED_DATA_DIR) / "kitti00";
  const bool real = fs::is_directory(kitti);
  const std::string folder = real ? kitti.string() : MakeDrive().string();
  const std::string args = folder + Quick() + " --count 5";  // 4 pairs either way
  const fs::path sharded = dir_ / "sharded";

  const std::vector<RunResult> shards =
      RunShards("map " + args + " -o " + sharded.string() + " --json", 3);
  int pairs = 0;
  for (const RunResult& r : shards) {
    ASSERT_EQ(r.exit_code, 0) << r.err;
    pairs += json::parse(r.out)["pairs"].get<int>();
  }
  EXPECT_EQ(pairs, 4);
  EXPECT_TRUE(fs::exists(sharded / "run.json"));
  EXPECT_FALSE(fs::exists(sharded / "map.bt")) << "a shard writes no map";
  EXPECT_FALSE(fs::exists(sharded / "trajectory.kitti"));

  // Shard 1/3 owns pairs 0 and 3. Killed after its first pair: the second
  // file is missing and a staging file is left over. The rerun redoes only that pair.
  fs::remove(sharded / "pairs" / "000003-000004.json");
  std::ofstream(sharded / "pairs" / "000003-000004.json.123-4.tmp") << "{\"sou";
  const RunResult rerun = Run("map " + args + " -o " + sharded.string() + " --shard 1/3 --json");
  ASSERT_EQ(rerun.exit_code, 0) << rerun.err;
  const json rerun_summary = json::parse(rerun.out);
  EXPECT_EQ(rerun_summary["pairs"], 2);
  EXPECT_EQ(rerun_summary["pairs_reused"], 1);

  const fs::path merged = dir_ / "merged";
  const RunResult merge = Run("merge " + sharded.string() + " -o " + merged.string() + " --json");
  ASSERT_EQ(merge.exit_code, 0) << merge.err;
  EXPECT_EQ(json::parse(merge.out)["pairs"], 4);

  const fs::path single = dir_ / "single";
  const RunResult map = Run("map " + args + " -o " + single.string());
  ASSERT_EQ(map.exit_code, 0) << map.err;

  for (const char* name : {"map.bt", "map.ot", "trajectory.tum", "preview.png"}) {
    EXPECT_TRUE(fs::exists(merged / name)) << name;
  }
  EXPECT_EQ(Slurp(merged / "trajectory.kitti"), Slurp(single / "trajectory.kitti"));
  const json merged_pairs = json::parse(Slurp(merged / "pairs.json"));
  const json single_pairs = json::parse(Slurp(single / "pairs.json"));
  ASSERT_EQ(merged_pairs.size(), 4u);
  ASSERT_EQ(single_pairs.size(), 4u);
  for (size_t i = 0; i < 4; ++i) {
    for (const char* key :
         {"source", "target", "transform", "objective", "fitness", "inlier_rmse", "seed"}) {
      EXPECT_EQ(merged_pairs[i][key], single_pairs[i][key]) << "pair " << i << " " << key;
    }
  }
}

TEST_F(ShardCli, MergeRefusesMissingPairsAndMismatchedSettings) {
  const std::string folder = MakeDrive().string();
  const fs::path a = dir_ / "a", b = dir_ / "b";
  auto expect_bad = [this](const std::string& args, const std::string& message) {
    const RunResult r = Run(args);
    EXPECT_EQ(r.exit_code, 2) << args << "\n" << r.err;
    EXPECT_THAT(r.err, HasSubstr(message)) << args;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  };

  expect_bad("map " + folder + " -o " + a.string() + " --shard 4/3", "K/N");
  expect_bad("map " + folder + " -o " + a.string() + " --shard two", "K/N");
  expect_bad("map " + folder + " -o " + a.string() + " --shard 1/2 --pairing overlap",
             "overlap pairing");
  expect_bad("merge " + a.string() + " -o " + a.string(), "run.json: no such file");

  // Shard 1/2 owns pairs 0 and 2; without shard 2/2 the merge names 1->2 and 3->4.
  const RunResult first = Run("map " + folder + Quick() + " -o " + a.string() + " --shard 1/2");
  ASSERT_EQ(first.exit_code, 0) << first.err;
  expect_bad("merge " + a.string() + " -o " + a.string(),
             "2 of 4 pair results missing (1->2, 3->4)");
  EXPECT_FALSE(fs::exists(a / "map.bt"));

  // Shard 2/2 with another seed: refused in the same folder, and refused by
  // the merge when it ran in a folder of its own.
  expect_bad("map " + folder + Quick(6) + " -o " + a.string() + " --shard 2/2",
             "another run's settings (seed: 5 vs 6)");
  const RunResult second = Run("map " + folder + Quick(6) + " -o " + b.string() + " --shard 2/2");
  ASSERT_EQ(second.exit_code, 0) << second.err;
  expect_bad("merge " + a.string() + " " + b.string() + " -o " + a.string(),
             "differs from " + (a / "run.json").string() + " (seed: 5 vs 6)");

  // A pair file whose settings were changed behind the manifest's back.
  const fs::path file = a / "pairs" / "000000-000001.json";
  json pair = json::parse(Slurp(file));
  pair["settings"]["config"]["voxel"] = 0.5;
  std::ofstream(file) << pair.dump();
  const RunResult fill = Run("map " + folder + Quick() + " -o " + a.string() + " --shard 2/2");
  ASSERT_EQ(fill.exit_code, 0) << fill.err;
  expect_bad("merge " + a.string() + " -o " + a.string(),
             "000000-000001.json: computed with other settings");
}

}  // namespace
}  // namespace boicp
