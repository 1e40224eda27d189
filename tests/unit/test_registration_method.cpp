// The method interface and its registry: names, errors, and core's two
// methods on a generated street, where "bo-icp" answers as RegisterPair does
// and "icp" aligns a close pair and calls a far one doubtful.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <memory>

#include "boicp/io/synthetic_scene.hpp"
#include "boicp/registration/registration_method.hpp"
#include "evaluation.hpp"

namespace boicp {
namespace {

using ::testing::ElementsAre;
using ::testing::HasSubstr;

struct StreetScans {
  Points source, target;
  Transform truth;  // T_target_source
};

StreetScans MakeStreetScans(double yaw, const Eigen::Vector3d& offset) {
  const Points world = MakeSyntheticStreet(11, 15.0);
  const Transform T_world_target = PoseFromYawTranslation(0.0, {0.0, 0.0, 1.8});
  const Transform T_world_source = PoseFromYawTranslation(yaw, offset);
  return {SimulateScan(world, T_world_source, 30.0, 0.01, 1),
          SimulateScan(world, T_world_target, 30.0, 0.01, 2),
          T_world_target.inverse() * T_world_source};
}

BoIcpConfig MethodTestConfig() {
  BoIcpConfig config = PresetConfig("A");
  config.automatic.clear();
  config.rotation_bounds = Eigen::Vector3d(0.2, 0.2, M_PI);
  config.evaluation_points = 1000;
  config.seed = 5;
  config.threads = 2;
  return config;
}

TEST(MethodRegistry, ListsCoreMethodsInOrderAndNamesTheKnownOnesForAnUnknownName) {
  const MethodRegistry methods = CoreMethods();
  EXPECT_THAT(methods.Names(), ElementsAre("bo-icp", "icp"));
  EXPECT_TRUE(methods.Contains(kDefaultMethod));
  EXPECT_FALSE(methods.Contains("ransac"));
  try {
    methods.Create("ransac", MethodTestConfig());
    FAIL() << "an unknown method was created";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("unknown registration method 'ransac'"));
    EXPECT_THAT(e.what(), HasSubstr("bo-icp, icp"));
  }
  EXPECT_THROW(methods.Require("ransac"), InputError);
  EXPECT_NO_THROW(methods.Require("icp"));
}

TEST(MethodRegistry, RefusesATakenOrEmptyNameAndCreatesWithTheNameAsked) {
  MethodRegistry methods = CoreMethods();
  const MethodFactory factory = [](const BoIcpConfig& config) {
    return CoreMethods().Create("icp", config);
  };
  EXPECT_THROW(methods.Add("icp", "again", factory), std::invalid_argument);
  EXPECT_THROW(methods.Add("", "nameless", factory), std::invalid_argument);
  std::string asked;
  methods.Add("spy", "records the config's method", [&asked](const BoIcpConfig& config) {
    asked = config.method;
    return CoreMethods().Create("icp", config);
  });
  EXPECT_EQ(methods.Summary("spy"), "records the config's method");
  methods.Create("spy", MethodTestConfig());
  EXPECT_EQ(asked, "spy");
}

TEST(CoreMethods, NeedFinalSettingsAndRefuseAScanAnotherMethodPrepared) {
  BoIcpConfig automatic = MethodTestConfig();
  automatic.automatic = {"voxel"};
  EXPECT_THROW(CoreMethods().Create("bo-icp", automatic), std::invalid_argument);
  BoIcpConfig invalid = MethodTestConfig();
  invalid.voxel = -1.0;
  EXPECT_THROW(CoreMethods().Create("icp", invalid), InputError);

  struct Foreign final : PreparedScan {};
  const auto method = CoreMethods().Create("icp", MethodTestConfig());
  const StreetScans pair = MakeStreetScans(0.0, {0.3, 0.1, 1.8});
  const auto prepared = method->Prepare(pair.source);
  EXPECT_THROW(method->Register(Foreign(), *prepared, {}), std::invalid_argument);
}

TEST(CoreMethods, BoIcpAnswersAsRegisterPairDoesOnTheSameSettings) {
  const StreetScans pair = MakeStreetScans(2.3, {1.2, 0.4, 1.8});
  for (const Budget budget : {Budget::kAuto, Budget::kFixed}) {
    BoIcpConfig config = MethodTestConfig();
    config.budget = budget;
    const RegistrationResult direct = RegisterPair(pair.source, pair.target, config);
    const RegistrationResult method =
        CoreMethods().Create("bo-icp", config)->RegisterClouds(pair.source, pair.target);
    EXPECT_EQ(method.transform, direct.transform) << BudgetName(budget);
    EXPECT_EQ(method.confidence, direct.confidence);
    EXPECT_EQ(method.evaluations, direct.evaluations);
    EXPECT_EQ(method.answered_by, direct.answered_by);
    EXPECT_LT(RotationErrorDeg(method.transform, pair.truth), 1.0);
    EXPECT_LT(TranslationErrorM(method.transform, pair.truth), 0.1);
  }
}

// One ICP run: a consecutive scan 0.5 m and 3 degrees away is aligned from
// the identity within 0.5 degrees and 5 cm, and trusted; the same scan turned
// by 132 degrees is beyond ICP's basin, and its answer is called doubtful.
TEST(CoreMethods, IcpAlignsACloseScanFromTheIdentityAndDoubtsAFarOne) {
  const auto icp = CoreMethods().Create("icp", MethodTestConfig());
  const StreetScans close = MakeStreetScans(0.05, {0.5, 0.1, 1.8});
  const RegistrationResult near = icp->RegisterClouds(close.source, close.target);
  EXPECT_LT(RotationErrorDeg(near.transform, close.truth), 0.5);
  EXPECT_LT(TranslationErrorM(near.transform, close.truth), 0.05);
  EXPECT_FALSE(near.doubtful);
  EXPECT_EQ(near.evaluations, 1);
  EXPECT_EQ(near.answered_by, Rung::kPrior);
  ASSERT_EQ(near.attempts.size(), 1u);
  EXPECT_TRUE(near.attempts[0].kept);

  const StreetScans far = MakeStreetScans(2.3, {1.2, 0.4, 1.8});
  const RegistrationResult lost = icp->RegisterClouds(far.source, far.target);
  EXPECT_GT(RotationErrorDeg(lost.transform, far.truth), 10.0);
  EXPECT_TRUE(lost.doubtful) << "confidence " << lost.confidence;

  // Given the truth as a prior, the same run starts there and stays.
  PairHints hints;
  hints.prior = far.truth;
  const RegistrationResult primed = icp->RegisterClouds(far.source, far.target, hints);
  EXPECT_LT(RotationErrorDeg(primed.transform, far.truth), 0.5);
  EXPECT_LT(TranslationErrorM(primed.transform, far.truth), 0.05);
}

}  // namespace
}  // namespace boicp
