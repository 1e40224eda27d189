#include "bench_options.hpp"

#include <algorithm>
#include <sstream>

#include <CLI/CLI.hpp>

#include "boicp/settings/settings_flags.hpp"
#include "boicp/util/types.hpp"
#include "methods.hpp"

namespace boicp::bench {
namespace {

std::vector<std::string> SplitList(const std::string& text) {
  std::vector<std::string> items;
  std::stringstream stream(text);
  std::string item;
  while (std::getline(stream, item, ',')) {
    if (!item.empty()) items.push_back(item);
  }
  return items;
}

std::vector<std::string> ParseMethods(const std::string& text) {
  const std::vector<std::string> requested = SplitList(text);
  if (requested.empty()) throw UsageError("--methods: empty list");
  for (const std::string& name : requested) {
    if (std::find(MethodNames().begin(), MethodNames().end(), name) == MethodNames().end()) {
      throw UsageError("--methods: unknown method '" + name + "'");
    }
  }
  // Canonical order, so tables and plots list methods the same way every run.
  std::vector<std::string> ordered;
  for (const std::string& name : MethodNames()) {
    if (std::find(requested.begin(), requested.end(), name) != requested.end()) {
      ordered.push_back(name);
    }
  }
  return ordered;
}

std::string MethodList() {
  std::string methods;
  for (const std::string& name : MethodNames()) methods += (methods.empty() ? "" : ",") + name;
  return methods;
}

// The registration settings the bench takes from the schema become overrides
// of the dataset table.
void ApplySchemaSettings(const settings::RequestedSettings& given, DatasetOverrides& o) {
  if (given.voxel && !(*given.voxel > 0.0)) throw UsageError("--voxel: must be positive");
  for (const auto& [flag, bounds] : {std::pair{"--rotation-bounds", given.rotation_bounds},
                                     std::pair{"--translation-bounds", given.translation_bounds}}) {
    if (bounds && (bounds->array() < 0.0).any()) {
      throw UsageError(std::string(flag) + ": values must be >= 0");
    }
  }
  o.voxel = given.voxel;
  o.rotation_bounds = given.rotation_bounds;
  o.translation_bounds = given.translation_bounds;
  o.retry_when_doubtful = !given.no_retry;
  o.icp_objective = given.icp_objective;
}

}  // namespace

BenchOptions ParseBenchOptions(int argc, const char* const* argv) {
  BenchOptions options;
  options.data_root = BOICP_SHARED_DATA_DIR;
  options.methods = MethodNames();
  for (int i = 0; i < argc; ++i) {
    options.command_line += (i == 0 ? "" : " ") + std::string(argv[i]);
  }
  DatasetOverrides& o = options.overrides;
  std::vector<std::string> datasets;
  settings::RequestedSettings given;
  settings::FlagTexts given_texts;

  CLI::App app("Accuracy and runtime of BO-ICP against its baselines", "boicp-bench");
  app.option_defaults()->multi_option_policy(CLI::MultiOptionPolicy::TakeLast);
  app.add_option_function<std::vector<std::string>>(
         "--pairs",
         [&](const std::vector<std::string>& lists) {
           for (const std::string& list : lists) {
             for (const std::string& csv : SplitList(list)) options.pairs_csvs.push_back(csv);
           }
         },
         "CSV[,CSV...]: pair lists to run (may be repeated)")
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
  app.add_option_function<std::string>(
      "--datasets", [&](const std::string& v) { datasets = SplitList(v); },
      "NAME[,NAME...]: DATA_ROOT/NAME/pairs.csv");
  app.add_option_function<int>(
         "--synthetic", [&](int n) { options.synthetic_pairs = n; },
         "Add N generated street pairs (no files needed)")
      ->check(CLI::PositiveNumber);
  app.add_option("--out", options.out_dir, "Output folder (required)");
  app.add_option_function<std::string>(
      "--methods", [&](const std::string& v) { options.methods = ParseMethods(v); },
      "M[,M...]; default all: " + MethodList());
  app.add_option_function<std::string>(
      "--perturb",
      [&](const std::string& v) {
        try {
          o.perturb = ParsePerturbationKind(v);
        } catch (const std::exception& e) {
          throw UsageError(std::string("--perturb: ") + e.what());
        }
      },
      "yaw|axis90|any|none: source perturbation (default: per dataset)");
  app.add_option_function<std::string>(
      "--field",
      [&](const std::string& v) {
        try {
          o.field = ParseFieldCondition(v);
        } catch (const std::exception& e) {
          throw UsageError(std::string("--field: ") + e.what());
        }
      },
      FieldConditionNames() +
          ": what is done to every loaded pair (default clean; "
          "bench/field_conditions.hpp)");
  app.add_option("--max-angle-deg", o.max_angle_deg, "Largest axis perturbation angle (default 90)")
      ->check(CLI::PositiveNumber);
  app.add_option("--seed", options.seed, "Base seed of every random choice")->capture_default_str();
  app.add_option("--threads", options.threads, "Thread budget of every method")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  settings::AddSettingFlags(app, settings::kBench, given, given_texts);
  app.add_option("--max-rot-deg", o.max_rot_deg, "Success threshold (default: per dataset)")
      ->check(CLI::PositiveNumber);
  app.add_option("--max-trans-m", o.max_trans_m, "Success threshold (default: per dataset)")
      ->check(CLI::PositiveNumber);
  app.add_option("--max-pairs", options.max_pairs, "First N pairs of each dataset (default all)")
      ->check(CLI::PositiveNumber);
  app.add_option("--data-root", options.data_root, "Folder of --datasets")->capture_default_str();
  app.add_option_function<std::string>(
      "--scaling", [&](const std::string& v) { options.scaling_datasets = SplitList(v); },
      "NAME[,NAME...]: also time bo-C against points and iterations on the first pair of "
      "these datasets");
  app.add_flag("--scaling-only", options.scaling_only,
               "Only the scaling study of the --scaling datasets");
  app.add_flag("--quick", options.quick, "Smoke-test budgets (see summary.md)");
  app.add_flag("--auto-settings", o.automatic_settings,
               "BO methods choose voxel and boxes from the clouds (no dataset table); the rest "
               "keep the table's");
  options.usage = app.help();

  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp&) {
    options.help = true;
    return options;
  } catch (const CLI::ParseError& e) {
    throw UsageError(e.what());
  }
  try {
    settings::ApplyFlagTexts(given_texts, settings::kBench, given);
  } catch (const InputError& e) {
    throw UsageError(e.what());
  }
  ApplySchemaSettings(given, o);

  for (const std::string& name : datasets) {
    options.pairs_csvs.push_back(options.data_root + "/" + name + "/pairs.csv");
  }
  if (options.pairs_csvs.empty() && options.synthetic_pairs == 0) {
    throw UsageError("no pairs: give --pairs CSV, --datasets NAME or --synthetic N");
  }
  if (options.out_dir.empty()) throw UsageError("--out DIR is required");
  if (options.scaling_only && options.scaling_datasets.empty()) {
    throw UsageError("--scaling-only needs --scaling NAME");
  }
  return options;
}

}  // namespace boicp::bench
