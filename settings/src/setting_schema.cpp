#include "boicp/settings/setting_schema.hpp"

#include <cmath>

namespace boicp::settings {
namespace {

using RS = RequestedSettings;
using C = BoIcpConfig;

constexpr double kInf = std::numeric_limits<double>::infinity();

constexpr unsigned kEveryFrontEnd = kRegister | kMap | kSubmit;
constexpr unsigned kMapFrontEnds = kMap | kSubmit;

constexpr const char* kNotInApi =
    "Not in the API (RegistrationConfig), so map and submit, whose runs must agree with the "
    "daemon's, leave it to the preset; only register takes it.";
constexpr const char* kNoMapInRegister = "register aligns one pair and builds no map.";
constexpr const char* kNoMergedCloudLocally =
    "register builds no map, and boicp map writes no merged PLY.";

// What one batch may ask of the daemon. The surrogate grows with the square
// of the samples and steps of a search, an evaluation's cost with its
// points, and a ray's with its length over the map's leaf size.
constexpr RequestLimits kUnbounded{};
constexpr RequestLimits kSearchSteps{-kInf, 1000.0};
constexpr RequestLimits kEvaluationPoints{-kInf, 1e6};
constexpr RequestLimits kRotationHalfWidths{-kInf, M_PI};
constexpr RequestLimits kTranslationHalfWidths{-kInf, 1000.0};  // metres
constexpr RequestLimits kRanges{-kInf, 1000.0};                 // metres
constexpr RequestLimits kCells{0.01, kInf};                     // metres

std::vector<SettingField> BuildSchema() {
  const ProtoMessage kReg = ProtoMessage::kRegistrationConfig;
  const ProtoMessage kMapMsg = ProtoMessage::kMapSettings;
  const ProtoMessage kNone = ProtoMessage::kNone;
  return {
      {"method", "--method", nullptr, "method", kReg, "method", kEveryFrontEnd,
       "bo-icp (BO-ICP, as --budget says) or icp (one ICP from the prior, else the identity, "
       "refined: for scans already close)",
       nullptr, PlainBinding<std::string>{&RS::method}, kUnbounded},
      {"preset", "--config", nullptr, "config", kReg, "preset", kEveryFrontEnd,
       "BO-ICP preset A, B or C (the paper's)", nullptr, PlainBinding<std::string>{&RS::preset},
       kUnbounded},
      {"mode", "--mode", nullptr, "mode", kReg, "mode", kEveryFrontEnd,
       "nested (rotation then translation) or 6dof", nullptr, PlainBinding<std::string>{&RS::mode},
       kUnbounded},
      {"icp_objective", "--icp-objective", nullptr, "icp_objective", kReg, "icp_objective",
       kEveryFrontEnd | kBench,
       "ICP of the search evaluations: plane (point-to-plane, fewer iterations) or point (the "
       "paper's point-to-point)",
       nullptr, PlainBinding<std::string>{&RS::icp_objective}, kUnbounded},
      {"budget", "--budget", nullptr, "budget", kReg, "budget", kEveryFrontEnd,
       "auto (cheapest first: prior, features, short search, full search, retry, each only "
       "while the answer is doubtful) or fixed (the paper's full search, then the retry)",
       nullptr, PlainBinding<std::string>{&RS::budget}, kUnbounded},
      // run.json's "sensor" is the sensor found and why.
      {"sensor", "--sensor", nullptr, "sensor_setting", kReg, "sensor", kEveryFrontEnd,
       "lidar, depth or object: the sensor the scans come from, which sets the rotation box, "
       "the map's up and the keyframe overlap; default auto: from the file format, else from "
       "the scans' geometry",
       nullptr, PlainBinding<std::string>{&RS::sensor}, kUnbounded},
      {"seed", "--seed", nullptr, "seed", kReg, "seed", kEveryFrontEnd,
       "Seed of every random choice; each pair's seed derives from it", nullptr,
       PlainBinding<uint64_t>{&RS::seed}, kUnbounded},
      {"fixed_settings", "--fixed-settings", nullptr, "fixed_settings", kReg, "fixed_settings",
       kEveryFrontEnd,
       "The preset's fixed voxel, bounds and map settings instead of choosing them from the scans",
       nullptr, PlainBinding<bool>{&RS::fixed_settings}, kUnbounded},
      {"no_retry", "--no-retry", nullptr, "no_retry", kReg, "no_retry", kEveryFrontEnd | kBench,
       "Never search a doubtful pair again", nullptr, PlainBinding<bool>{&RS::no_retry},
       kUnbounded},
      {"voxel", "--voxel", nullptr, "voxel", kReg, "voxel", kEveryFrontEnd | kBench,
       "Search voxel (metres); default: from the scans", nullptr,
       OptionalBinding<double>{&RS::voxel, &C::voxel}, kUnbounded},
      {"random_samples", "--random-samples", nullptr, "random_samples", kReg, "random_samples",
       kEveryFrontEnd, "N_r: space-filling samples per search stage; default: the preset's",
       nullptr, OptionalBinding<int>{&RS::random_samples, &C::random_samples}, kSearchSteps},
      {"iterations", "--iterations", nullptr, "iterations", kReg, "iterations", kEveryFrontEnd,
       "N: BO iterations per search stage; default: the preset's", nullptr,
       OptionalBinding<int>{&RS::iterations, &C::iterations}, kSearchSteps},
      {"rotation_bounds", "--rotation-bounds", nullptr, "rotation_bounds", kReg, "rotation_bounds",
       kEveryFrontEnd | kBench,
       "Half-widths roll,pitch,yaw (radians, or pi); default: from the sensor", nullptr,
       OptionalBinding<Eigen::Vector3d>{&RS::rotation_bounds, &C::rotation_bounds},
       kRotationHalfWidths},
      {"translation_bounds", "--translation-bounds", nullptr, "translation_bounds", kReg,
       "translation_bounds", kEveryFrontEnd | kBench,
       "Half-widths x,y,z (metres); default: from the scans", nullptr,
       OptionalBinding<Eigen::Vector3d>{&RS::translation_bounds, &C::translation_bounds},
       kTranslationHalfWidths},
      {"evaluation_points", "--evaluation-points", nullptr, "evaluation_points", kReg,
       "evaluation_points", kEveryFrontEnd, "Source points each evaluation uses (0 = all)", nullptr,
       OptionalBinding<uint64_t>{&RS::evaluation_points, &C::evaluation_points}, kEvaluationPoints},
      {"refine_voxel", "--refine-voxel", nullptr, "refine_voxel", kReg, "refine_voxel",
       kEveryFrontEnd, "Finest voxel of the final ICP (metres); default: from the scans", nullptr,
       OptionalBinding<double>{&RS::refine_voxel, &C::refine_voxel, &C::EffectiveRefineVoxel},
       kUnbounded},
      {"max_correspondence", "--max-correspondence", nullptr, "max_correspondence", kReg,
       "max_correspondence", kEveryFrontEnd,
       "ICP correspondence gate during the search (metres); default 3 x voxel", nullptr,
       OptionalBinding<double>{&RS::max_correspondence, &C::max_correspondence_distance,
                               &C::EffectiveMaxCorrespondence},
       kUnbounded},
      {"min_range", "--min-range", nullptr, "min_range", kReg, "min_range", kEveryFrontEnd,
       "Drop scan points closer to the sensor than this (metres)", nullptr,
       OptionalBinding<double>{&RS::min_range, &C::min_range}, kRanges},
      // --max-range of map and submit is the OctoMap ray cut.
      {"scan_max_range", "--max-range", "--scan-max-range", "scan_max_range", kReg, "max_range",
       kEveryFrontEnd, "Drop scan points farther from the sensor than this (metres; 0 = none)",
       nullptr, OptionalBinding<double>{&RS::scan_max_range, &C::max_range}, kRanges},
      {"objective_truncation", "--objective-truncation", nullptr, "objective_truncation", kNone, "",
       kRegister, "Clipping distance of the search objective (metres); default 1.5 x voxel",
       kNotInApi,
       OptionalBinding<double>{&RS::objective_truncation, &C::objective_truncation,
                               &C::EffectiveTruncation},
       kUnbounded},
      {"icp_iterations", "--icp-iterations", nullptr, "icp_iterations", kNone, "", kRegister,
       "ICP iterations per evaluation", kNotInApi,
       OptionalBinding<int>{&RS::icp_iterations, &C::icp_max_iterations}, kUnbounded},
      {"coarse_icp_points", "--coarse-icp-points", nullptr, "coarse_icp_points", kNone, "",
       kRegister, "Points each evaluation's ICP starts on before it finishes on all (0 = all)",
       kNotInApi, OptionalBinding<uint64_t>{&RS::coarse_icp_points, &C::coarse_icp_points},
       kUnbounded},
      {"threads", "--threads", nullptr, "threads", kNone, "", kRegister,
       "Threads for the search and the refinement (default: every core; the answer does not "
       "depend on it)",
       "Map and the daemon run one registration thread per pair and spread pairs over threads "
       "(map --threads, boicpd --registration-threads).",
       OptionalBinding<int>{&RS::threads, &C::threads}, kUnbounded},

      {"resolution", "--resolution", nullptr, "resolution", kMapMsg, "resolution", kMapFrontEnds,
       "OctoMap leaf size (metres); default: from the scans", kNoMapInRegister,
       OptionalBinding<double>{&RS::resolution}, kCells},
      {"max_range", "--max-range", nullptr, "max_range", kMapMsg, "max_range", kMapFrontEnds,
       "OctoMap ray length (metres), 0 = no limit; default: from the scans", kNoMapInRegister,
       OptionalBinding<double>{&RS::max_range}, kRanges},
      {"prob_hit", "--prob-hit", nullptr, "prob_hit", kMapMsg, "sensor_model.prob_hit",
       kMapFrontEnds, "OctoMap hit probability, in (0.5, 1); default 0.7", kNoMapInRegister,
       OptionalBinding<double>{&RS::prob_hit}, kUnbounded},
      {"prob_miss", "--prob-miss", nullptr, "prob_miss", kMapMsg, "sensor_model.prob_miss",
       kMapFrontEnds, "OctoMap miss probability, in (0, 0.5); default 0.4", kNoMapInRegister,
       OptionalBinding<double>{&RS::prob_miss}, kUnbounded},
      {"clamp_min", "--clamp-min", nullptr, "clamp_min", kMapMsg, "sensor_model.clamp_min",
       kMapFrontEnds, "OctoMap lower clamping probability; default 0.12", kNoMapInRegister,
       OptionalBinding<double>{&RS::clamp_min}, kUnbounded},
      {"clamp_max", "--clamp-max", nullptr, "clamp_max", kMapMsg, "sensor_model.clamp_max",
       kMapFrontEnds, "OctoMap upper clamping probability; default 0.97", kNoMapInRegister,
       OptionalBinding<double>{&RS::clamp_max}, kUnbounded},
      {"cloud_voxel", "--cloud-voxel", nullptr, "cloud_voxel", kMapMsg, "cloud_voxel", kSubmit,
       "Voxel of the exported merged PLY (metres); default: the resolution", kNoMergedCloudLocally,
       OptionalBinding<double>{&RS::cloud_voxel}, kCells},
      {"loops", "--loops", nullptr, "loops", kMapMsg, "loops", kMapFrontEnds,
       "auto (look for loop closures on the chained poses and keep those registration trusts) "
       "or off (only the pairing's pairs)",
       kNoMapInRegister, PlainBinding<std::string>{&RS::loops}, kUnbounded},
      {"untrusted_scans", "--untrusted-scans", nullptr, "untrusted_scans", kMapMsg,
       "untrusted_scans", kMapFrontEnds,
       "leave-out (a scan no trusted pair ties to the others is named and not fused) or place "
       "(named, and fused where its best doubtful pair puts it)",
       kNoMapInRegister, PlainBinding<std::string>{&RS::untrusted_scans}, kUnbounded},
  };
}

}  // namespace

const std::vector<SettingField>& SettingSchema() {
  static const std::vector<SettingField> schema = BuildSchema();
  return schema;
}

const SettingField* FindSetting(const std::string& name) {
  for (const SettingField& field : SettingSchema()) {
    if (name == field.name) return &field;
  }
  return nullptr;
}

const char* FlagFor(const SettingField& field, Frontend frontend) {
  const bool map_side = frontend == kMap || frontend == kSubmit;
  return map_side && field.map_flag != nullptr ? field.map_flag : field.flag;
}

}  // namespace boicp::settings
