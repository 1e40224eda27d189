// Presets and config validation.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "boicp/registration/config.hpp"
#include "boicp/util/types.hpp"

namespace boicp {
namespace {

using ::testing::HasSubstr;

struct PresetCase {
  std::string name;
  int random_samples, iterations;
  double voxel;
};

class Presets : public ::testing::TestWithParam<PresetCase> {};

TEST_P(Presets, MatchThePaper) {
  const BoIcpConfig c = PresetConfig(GetParam().name);
  EXPECT_EQ(c.random_samples, GetParam().random_samples);
  EXPECT_EQ(c.iterations, GetParam().iterations);
  EXPECT_DOUBLE_EQ(c.voxel, GetParam().voxel);
  EXPECT_NO_THROW(ValidateConfig(c));
}

INSTANTIATE_TEST_SUITE_P(Paper, Presets,
                         ::testing::Values(PresetCase{"A", 10, 20, 0.7},
                                           PresetCase{"b", 20, 35, 0.7},
                                           PresetCase{"C", 30, 60, 0.6}));

TEST(Config, DefaultsAreThePapersBounds) {
  const BoIcpConfig c = PresetConfig("C");
  EXPECT_EQ(c.translation_bounds, Eigen::Vector3d(4, 2, 1));
  EXPECT_EQ(c.rotation_bounds, Eigen::Vector3d(M_PI, M_PI / 2, M_PI));
  EXPECT_DOUBLE_EQ(c.EffectiveMaxCorrespondence(), 3 * 0.6);
  EXPECT_DOUBLE_EQ(c.EffectiveRefineVoxel(), 0.15);
}

std::string ValidationMessage(const BoIcpConfig& c) {
  try {
    ValidateConfig(c);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(Config, BoundsWithinAThousandthOfPiArePi) {
  const Eigen::Vector3d snapped = SnapRotationBounds(Eigen::Vector3d(3.14159, 1.5705, 3.1416));
  EXPECT_EQ(snapped, Eigen::Vector3d(M_PI, M_PI / 2, M_PI));
  EXPECT_EQ(SnapRotationBounds(Eigen::Vector3d(3.13, 1.56, 0.2)), Eigen::Vector3d(3.13, 1.56, 0.2));
  BoIcpConfig c = PresetConfig("C");
  c.rotation_bounds = Eigen::Vector3d(3.1416, 1.5709, 3.1416);  // a hair above pi: still pi
  EXPECT_NO_THROW(ValidateConfig(c));
}

TEST(Config, PresetsLeaveScaleAndBoxesToTheData) {
  BoIcpConfig c = PresetConfig("C");
  EXPECT_EQ(c.automatic, kAutoRegistrationFields);
  c.MarkSet("voxel");
  c.MarkSet("rotation_bounds");
  EXPECT_EQ(c.automatic, (std::vector<std::string>{"refine_voxel", "objective_truncation",
                                                   "translation_bounds"}));
  c.automatic.push_back("seed");
  EXPECT_THAT(ValidationMessage(c), HasSubstr("'seed'"));
}

TEST(Config, RejectsInvalidFieldsByName) {
  BoIcpConfig c = PresetConfig("A");
  c.voxel = 0.0;
  EXPECT_THAT(ValidationMessage(c), HasSubstr("voxel"));
  c = PresetConfig("A");
  c.translation_bounds[1] = -1;
  EXPECT_THAT(ValidationMessage(c), HasSubstr("translation bounds"));
  c = PresetConfig("A");
  c.rotation_bounds[1] = 2.0;
  EXPECT_THAT(ValidationMessage(c), HasSubstr("pitch"));
  c = PresetConfig("A");
  c.rotation_bounds.setZero();
  c.translation_bounds.setZero();
  EXPECT_THAT(ValidationMessage(c), HasSubstr("nothing to search"));
  c = PresetConfig("A");
  c.random_samples = 0;
  EXPECT_THAT(ValidationMessage(c), HasSubstr("random samples"));
  c = PresetConfig("A");
  c.max_range = 1.0;
  c.min_range = 2.0;
  EXPECT_THAT(ValidationMessage(c), HasSubstr("range"));
  c = PresetConfig("A");
  c.finish_icp_iterations = 0;
  EXPECT_THAT(ValidationMessage(c), HasSubstr("finishing iterations"));
  EXPECT_THROW(PresetConfig("D"), InputError);
  EXPECT_THROW(ParseSearchMode("5dof"), InputError);
}

}  // namespace
}  // namespace boicp
