// `boicp register` and `boicp demo-data` as a script sees them: exit codes,
// one JSON object on stdout, one-line errors on stderr.

#include <sys/wait.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <set>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include "../support/files_and_processes.hpp"

namespace {
using boicp::test::RunCaptured;
using boicp::test::RunResult;
using boicp::test::Slurp;

using ::testing::HasSubstr;
namespace fs = std::filesystem;

class Cli : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("boicp_cli_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  RunResult Run(const std::string& args) {
    return RunCaptured(std::string(BOICP_CLI_PATH) + " " + args, dir_);
  }

  fs::path dir_;
};

// The rungs of the ladder, as answered_by names them.
const std::set<std::string> kRungs = {"prior", "features", "short-search", "full-search", "retry"};

// The attempts of a `register --json` answer: exactly one is kept, its fit
// is the answer's, and the evaluations add up to the answer's.
void ExpectAttemptsAddUp(const nlohmann::json& j) {
  int kept = 0, evaluations = 0;
  for (const nlohmann::json& attempt : j["attempts"]) {
    evaluations += attempt["evaluations"].get<int>();
    if (!attempt["kept"].get<bool>()) continue;
    ++kept;
    EXPECT_EQ(attempt["fitness"], j["fitness"]);
  }
  EXPECT_EQ(kept, 1);
  EXPECT_EQ(evaluations, j["evaluations"]);
}

// --sensor replaces what the geometry says: the street's ring taken as an
// object's scan gets every rotation, and the JSON says who decided.
TEST_F(Cli, RegisterSensorSettingDecidesTheSensorAndSaysSo) {
  ASSERT_EQ(Run("demo-data --out " + dir_.string()).exit_code, 0);
  const std::string args = "register --source " + (dir_ / "source.xyz").string() + " --target " +
                           (dir_ / "target.xyz").string() + " --config A --seed 3 --json";
  const RunResult r = Run(args + " --sensor object");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["sensor"]["type"], "other");
  EXPECT_EQ(j["sensor"]["why"], "set by --sensor");
  EXPECT_EQ(j["config"]["sensor"], "object");
  EXPECT_EQ(j["config"]["rotation_bounds"], nlohmann::json({M_PI, M_PI / 2, M_PI}));

  const RunResult bad = Run(args + " --sensor camera");
  EXPECT_EQ(bad.exit_code, 2);
  EXPECT_THAT(
      bad.err,
      HasSubstr("--sensor: unknown sensor 'camera' (expected lidar, depth, object or auto)"));
}

TEST_F(Cli, RegisterDemoPairPrintsOneJsonObjectNearTheTruth) {
  ASSERT_EQ(Run("demo-data --out " + dir_.string()).exit_code, 0);
  const std::string args = "register --source " + (dir_ / "source.xyz").string() + " --target " +
                           (dir_ / "target.xyz").string() +
                           " --config A --seed 3 --rotation-bounds 0.2,0.2,pi";
  const RunResult r = Run(args + " --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);  // throws if anything else is on stdout
  for (const char* key : {"transform", "objective", "fitness", "inlier_rmse", "confidence",
                          "answered_by", "evaluations", "runtime_s", "config"}) {
    EXPECT_TRUE(j.contains(key)) << key;
  }
  std::ifstream truth_file(dir_ / "truth.txt");
  double truth[16];
  for (double& v : truth) truth_file >> v;
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(j["transform"][i][3].get<double>(), truth[4 * i + 3], 0.1) << "row " << i;
    for (int k = 0; k < 3; ++k)
      EXPECT_NEAR(j["transform"][i][k].get<double>(), truth[4 * i + k], 0.02);
  }
  EXPECT_EQ(j["config"]["preset"], "A");
  EXPECT_EQ(j["config"]["budget"], "auto");
  EXPECT_EQ(j["config"]["sensor"], "auto");
  // The rotation box was given ("pi" is pi); the rest came from the clouds.
  EXPECT_EQ(j["config"]["rotation_bounds"][2].get<double>(), M_PI);
  EXPECT_EQ(j["auto"], nlohmann::json({"voxel", "refine_voxel", "objective_truncation",
                                       "translation_bounds"}));
  for (const nlohmann::json& name : j["auto"]) {
    EXPECT_TRUE(j["config"].contains(name.get<std::string>())) << name << " names no setting";
  }
  EXPECT_EQ(j["far_returns"], nlohmann::json({{"source", 0}, {"target", 0}}));
  // The generated street is a full ring of a LiDAR 1.8 m above the road.
  EXPECT_EQ(j["sensor"]["type"], "lidar");
  EXPECT_THAT(j["sensor"]["why"].get<std::string>(), HasSubstr("ring covering 360 deg"));
  EXPECT_THAT(j["sensor"]["why"].get<std::string>(), HasSubstr("m below the origin"));
  EXPECT_FALSE(j["doubtful"].get<bool>());
  // A right answer puts next to none of its points where the target's
  // sensor saw through.
  EXPECT_GE(j["seen_through"].get<double>(), 0.0);
  EXPECT_LT(j["seen_through"].get<double>(), 0.05);
  // The answer lies inside its search box.
  EXPECT_GE(j["search_reach"].get<double>(), 0.0);
  EXPECT_LE(j["search_reach"].get<double>(), 1.0);
  EXPECT_TRUE(j["unconstrained"].is_array());
  EXPECT_GT(j["constrained_share"].get<double>(), 0.0);
  // Some rung of the ladder answered: one attempt kept.
  EXPECT_EQ(kRungs.count(j["answered_by"].get<std::string>()), 1u) << j["answered_by"];
  ASSERT_GE(j["attempts"].size(), 1u);
  ExpectAttemptsAddUp(j);

  // The plain text says it too.
  const RunResult text = Run(args + " -q");
  ASSERT_EQ(text.exit_code, 0) << text.err;
  EXPECT_THAT(text.out, HasSubstr("answered_by " + j["answered_by"].get<std::string>() + "\n"));
  EXPECT_THAT(text.out, HasSubstr("evaluations " + std::to_string(j["evaluations"].get<int>())));
}

// Returns 1-2 km out (rain, a reflection), 1 in 50 of the source's points:
// set aside when choosing the settings, counted, and the pair still
// registers near the truth.
TEST_F(Cli, FarReturnsAreCountedAndDoNotMoveTheSettings) {
  ASSERT_EQ(Run("demo-data --out " + dir_.string()).exit_code, 0);
  const std::string common = "register --target " + (dir_ / "target.xyz").string() +
                             " --config A --seed 3 --rotation-bounds 0.2,0.2,pi --json";
  const RunResult clean = Run(common + " --source " + (dir_ / "source.xyz").string());
  ASSERT_EQ(clean.exit_code, 0) << clean.err;

  std::ifstream in(dir_ / "source.xyz");
  std::ofstream out(dir_ / "source_far.xyz");
  std::string line;
  int lines = 0, added = 0;
  while (std::getline(in, line)) {
    out << line << "\n";
    if (++lines % 50 == 0) {
      const double angle = 0.1 * lines, range = 1000.0 + lines % 1000;
      out << range * std::cos(angle) << " " << range * std::sin(angle) << " 5\n";
      ++added;
    }
  }
  out.close();
  const RunResult far = Run(common + " --source " + (dir_ / "source_far.xyz").string());
  ASSERT_EQ(far.exit_code, 0) << far.err;
  EXPECT_THAT(far.err, HasSubstr(std::to_string(added) + " source and 0 target points set aside"));
  const nlohmann::json a = nlohmann::json::parse(clean.out), b = nlohmann::json::parse(far.out);
  EXPECT_EQ(b["far_returns"], nlohmann::json({{"source", added}, {"target", 0}}));
  const double voxel = a["config"]["voxel"].get<double>();
  EXPECT_NEAR(b["config"]["voxel"].get<double>(), voxel, 0.03 * voxel);
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(b["transform"][i][3].get<double>(), a["transform"][i][3].get<double>(), 0.1);
  }
}

// A source in millimetres against a target in metres is refused with both
// scales and the fix named; with that fix it registers as the metre pair.
TEST_F(Cli, ScansInOtherUnitsAreAnErrorThatScaleSourceFixes) {
  ASSERT_EQ(Run("demo-data --out " + dir_.string()).exit_code, 0);
  std::ifstream in(dir_ / "source.xyz");
  std::ofstream out(dir_ / "source_mm.xyz");
  double x = 0.0, y = 0.0, z = 0.0;
  out.precision(12);
  while (in >> x >> y >> z) out << 1000.0 * x << " " << 1000.0 * y << " " << 1000.0 * z << "\n";
  out.close();
  const std::string common = "register --target " + (dir_ / "target.xyz").string() +
                             " --config A --seed 3 --rotation-bounds 0.2,0.2,pi --json";
  const RunResult refused = Run(common + " --source " + (dir_ / "source_mm.xyz").string());
  EXPECT_EQ(refused.exit_code, 2);
  EXPECT_THAT(refused.err, HasSubstr("differ in scale by a factor of about 1000"));
  EXPECT_THAT(refused.err, HasSubstr("do they share units?"));
  EXPECT_THAT(refused.err, HasSubstr("--scale-source 0.001"));

  const RunResult metres = Run(common + " --source " + (dir_ / "source.xyz").string());
  const RunResult scaled =
      Run(common + " --scale-source 0.001 --source " + (dir_ / "source_mm.xyz").string());
  ASSERT_EQ(metres.exit_code, 0) << metres.err;
  ASSERT_EQ(scaled.exit_code, 0) << scaled.err;
  const nlohmann::json a = nlohmann::json::parse(metres.out), b = nlohmann::json::parse(scaled.out);
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 4; ++j) {
      EXPECT_NEAR(b["transform"][i][j].get<double>(), a["transform"][i][j].get<double>(), 0.01);
    }
  }
  EXPECT_EQ(Run(common + " --scale-source 0 --source " + (dir_ / "source.xyz").string()).exit_code,
            2);
}

// The paper's search, as before the ladder: nested, (10 + 20) evaluations a
// stage, and only the retry of a doubtful answer after it.
TEST_F(Cli, FixedBudgetRunsThePapersSearch) {
  ASSERT_EQ(Run("demo-data --out " + dir_.string()).exit_code, 0);
  const RunResult r =
      Run("register --source " + (dir_ / "source.xyz").string() + " --target " +
          (dir_ / "target.xyz").string() +
          " --config A --seed 3 --rotation-bounds 0.2,0.2,pi --budget fixed --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["config"]["budget"], "fixed");
  ASSERT_GE(j["attempts"].size(), 1u);
  EXPECT_EQ(j["attempts"][0]["kind"], "search");
  EXPECT_EQ(j["attempts"][0]["mode"], "nested");
  EXPECT_EQ(j["attempts"][0]["evaluations"], 60);
  for (const nlohmann::json& attempt : j["attempts"]) {
    EXPECT_THAT(attempt["kind"].get<std::string>(), ::testing::AnyOf("search", "wider-refinement"));
  }
  const std::string rung = j["answered_by"];
  EXPECT_THAT(rung, ::testing::AnyOf("full-search", "retry"));
  if (j["attempts"].size() == 1) {
    EXPECT_EQ(rung, "full-search");
  }
  ExpectAttemptsAddUp(j);
}

// --method icp: one refinement from the identity, assessed like any answer.
// The demo pair is turned beyond ICP's basin, so the answer is doubtful, as
// it must be; the default method finds it.
TEST_F(Cli, IcpMethodRefinesOnceAndSaysWhenItIsLost) {
  ASSERT_EQ(Run("demo-data --out " + dir_.string()).exit_code, 0);
  const std::string pair = "register --source " + (dir_ / "source.xyz").string() + " --target " +
                           (dir_ / "target.xyz").string() + " --seed 3 --json";
  const RunResult icp = Run(pair + " --method icp");
  ASSERT_EQ(icp.exit_code, 0) << icp.err;
  const nlohmann::json j = nlohmann::json::parse(icp.out);
  EXPECT_EQ(j["config"]["method"], "icp");
  EXPECT_EQ(j["evaluations"], 1);
  EXPECT_EQ(j["answered_by"], "prior");
  ASSERT_EQ(j["attempts"].size(), 1u);
  EXPECT_EQ(j["attempts"][0]["kind"], "prior");
  EXPECT_TRUE(j["doubtful"].get<bool>()) << j["confidence"];
  const RunResult bo = Run(pair);
  ASSERT_EQ(bo.exit_code, 0) << bo.err;
  const nlohmann::json b = nlohmann::json::parse(bo.out);
  EXPECT_EQ(b["config"]["method"], "bo-icp");
  EXPECT_FALSE(b["doubtful"].get<bool>());
}

TEST_F(Cli, FixedSettingsAndNoRetry) {
  ASSERT_EQ(Run("demo-data --out " + dir_.string()).exit_code, 0);
  const RunResult r = Run("register --source " + (dir_ / "source.xyz").string() + " --target " +
                          (dir_ / "target.xyz").string() +
                          " --config A --seed 3 --iterations 5 --fixed-settings --no-retry"
                          " --budget fixed --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_TRUE(j["auto"].empty());
  EXPECT_DOUBLE_EQ(j["config"]["voxel"].get<double>(), 0.7);
  EXPECT_EQ(j["config"]["translation_bounds"], nlohmann::json({4.0, 2.0, 1.0}));
  EXPECT_TRUE(j["config"]["no_retry"].get<bool>());
  // The "0 = from the voxel" settings are reported as used.
  EXPECT_DOUBLE_EQ(j["config"]["max_correspondence"].get<double>(), 3.0 * 0.7);
  EXPECT_DOUBLE_EQ(j["config"]["objective_truncation"].get<double>(), 1.5 * 0.7);
  EXPECT_DOUBLE_EQ(j["config"]["refine_voxel"].get<double>(), 0.7 / 4.0);
  // The fixed budget without its retry: the one search answers.
  EXPECT_EQ(j["attempts"].size(), 1u);
  EXPECT_EQ(j["answered_by"], "full-search");
}

TEST_F(Cli, BadInputGivesOneLineErrorAndExitCode2) {
  ASSERT_EQ(Run("demo-data --out " + dir_.string()).exit_code, 0);
  const std::string pair =
      "--source " + (dir_ / "source.xyz").string() + " --target " + (dir_ / "target.xyz").string();
  std::ofstream(dir_ / "bad.bin") << "abc";
  std::ofstream(dir_ / "cloud.foo") << "1 2 3\n";
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"--source /nonexistent.pcd --target " + (dir_ / "target.xyz").string(), "nonexistent"},
      {"--source " + (dir_ / "bad.bin").string() + " --target " + (dir_ / "target.xyz").string(),
       "bad.bin"},
      {"--source " + (dir_ / "cloud.foo").string() + " --target " + (dir_ / "target.xyz").string(),
       "cloud.foo"},
      {pair + " --voxel -1", "voxel"},
      {pair + " --translation-bounds 1,2", "--translation-bounds"},
      {pair + " --rotation-bounds 0.2,0.2,tau", "--rotation-bounds"},
      {pair + " --config Z", "preset"},
      {pair + " --budget nope", "--budget: unknown budget 'nope' (expected auto or fixed)"},
      {pair + " --mode nope", "--mode: unknown search mode 'nope' (expected nested or 6dof)"},
      {pair + " --method ransac",
       "--method: unknown registration method 'ransac' (known: bo-icp, icp)"},
      {pair + " --max-range 0.01", "points after cropping"},
      {pair + " --prior /nonexistent_prior.txt", "nonexistent_prior"},
  };
  for (const auto& [args, expected] : cases) {
    const RunResult r = Run("register " + args + " --json");
    EXPECT_EQ(r.exit_code, 2) << args << "\n" << r.err;
    EXPECT_THAT(r.err, HasSubstr(expected)) << args;
    EXPECT_TRUE(r.out.empty()) << args;
    // Progress lines may precede it, but the error itself is exactly one line, the last.
    const std::string last_line = r.err.substr(r.err.rfind('\n', r.err.size() - 2) + 1);
    EXPECT_THAT(last_line, ::testing::StartsWith("boicp register: error: ")) << r.err;
    const size_t last_line_start = r.err.size() - last_line.size();
    EXPECT_GE(r.err.find("error"), last_line_start) << "no earlier line mentions an error\n"
                                                    << r.err;
  }
}

TEST_F(Cli, MissingRequiredFlagAndHelp) {
  EXPECT_EQ(Run("register --source x.pcd").exit_code, 2);
  const RunResult help = Run("register --help");
  EXPECT_EQ(help.exit_code, 0);
  for (const char* flag :
       {"--voxel", "--translation-bounds", "--rotation-bounds", "--format", "--intrinsics",
        "--intrinsics-file", "--depth-scale", "--prior", "--config", "--mode", "--seed", "--json",
        "--fixed-settings", "--no-retry", "--budget", "--method"}) {
    EXPECT_THAT(help.out, HasSubstr(flag));
  }
}

}  // namespace
