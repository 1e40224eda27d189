#include "bench_options.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <map>
#include <sstream>

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

double ParseDouble(const std::string& flag, const std::string& text) {
  try {
    size_t used = 0;
    const double value = std::stod(text, &used);
    if (used == text.size() && std::isfinite(value)) return value;
  } catch (const std::exception&) {
  }
  throw UsageError(flag + ": '" + text + "' is not a number");
}

double ParsePositive(const std::string& flag, const std::string& text) {
  const double value = ParseDouble(flag, text);
  if (value <= 0.0) throw UsageError(flag + ": must be positive, got '" + text + "'");
  return value;
}

long long ParseInteger(const std::string& flag, const std::string& text, long long min) {
  try {
    size_t used = 0;
    const long long value = std::stoll(text, &used);
    if (used == text.size() && value >= min) return value;
  } catch (const std::exception&) {
  }
  throw UsageError(flag + ": expected an integer >= " + std::to_string(min) + ", got '" + text +
                   "'");
}

Eigen::Vector3d ParseTriple(const std::string& flag, const std::string& text) {
  const std::vector<std::string> items = SplitList(text);
  if (items.size() != 3) throw UsageError(flag + ": expected X,Y,Z, got '" + text + "'");
  Eigen::Vector3d values;
  for (int k = 0; k < 3; ++k) {
    values[k] = ParseDouble(flag, items[k]);
    if (values[k] < 0.0) throw UsageError(flag + ": values must be >= 0, got '" + text + "'");
  }
  return values;
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

}  // namespace

std::string UsageText() {
  std::string methods;
  for (const std::string& name : MethodNames()) methods += (methods.empty() ? "" : ",") + name;
  return "usage: boicp-bench (--pairs CSV[,CSV...] | --datasets NAME[,NAME...] | --synthetic N)\n"
         "                   --out DIR [options]\n"
         "  --methods M[,M...]        default all: " +
         methods +
         "\n"
         "  --perturb yaw|axis90|any|none  source perturbation (default: per dataset)\n"
         "  --max-angle-deg A         largest axis perturbation angle (default 90)\n"
         "  --seed N                  base seed of every random choice (default 1)\n"
         "  --threads T               thread budget of every method (default 1)\n"
         "  --voxel V                 search voxel, metres (default: per dataset)\n"
         "  --rotation-bounds R,P,Y   search half-widths, radians (default: per dataset)\n"
         "  --translation-bounds X,Y,Z  search half-widths, metres (default: per dataset)\n"
         "  --max-rot-deg D --max-trans-m M  success thresholds (default: per dataset)\n"
         "  --max-pairs N             first N pairs of each dataset (default all)\n"
         "  --data-root DIR           folder of --datasets (default the shared data)\n"
         "  --scaling NAME[,NAME...]  also time bo-C against points and iterations\n"
         "                            on the first pair of these datasets\n"
         "  --synthetic N             add N generated street pairs (no files needed)\n"
         "  --scaling-only            only the scaling study of the --scaling datasets\n"
         "  --quick                   smoke-test budgets (see summary.md)\n"
         "  --auto-settings           BO methods choose voxel and boxes from the clouds\n"
         "                            (no dataset table); the rest keep the table's\n"
         "  --no-retry                BO methods never search a doubtful pair again\n";
}

BenchOptions ParseBenchOptions(int argc, const char* const* argv) {
  BenchOptions options;
  options.data_root = BOICP_SHARED_DATA_DIR;
  options.methods = MethodNames();
  for (int i = 0; i < argc; ++i) {
    options.command_line += (i == 0 ? "" : " ") + std::string(argv[i]);
  }
  std::vector<std::string> datasets;
  DatasetOverrides& o = options.overrides;

  using Handler = std::function<void(const std::string& flag, const std::string& value)>;
  const std::map<std::string, Handler> with_value = {
      {"--pairs",
       [&](auto&, auto& v) {
         for (const std::string& csv : SplitList(v)) options.pairs_csvs.push_back(csv);
       }},
      {"--datasets", [&](auto&, auto& v) { datasets = SplitList(v); }},
      {"--methods", [&](auto&, auto& v) { options.methods = ParseMethods(v); }},
      {"--perturb",
       [&](auto& f, auto& v) {
         try {
           o.perturb = ParsePerturbationKind(v);
         } catch (const std::exception& e) {
           throw UsageError(f + ": " + e.what());
         }
       }},
      {"--max-angle-deg", [&](auto& f, auto& v) { o.max_angle_deg = ParsePositive(f, v); }},
      {"--seed",
       [&](auto& f, auto& v) { options.seed = static_cast<uint64_t>(ParseInteger(f, v, 0)); }},
      {"--threads",
       [&](auto& f, auto& v) { options.threads = static_cast<int>(ParseInteger(f, v, 1)); }},
      {"--out", [&](auto&, auto& v) { options.out_dir = v; }},
      {"--voxel", [&](auto& f, auto& v) { o.voxel = ParsePositive(f, v); }},
      {"--rotation-bounds", [&](auto& f, auto& v) { o.rotation_bounds = ParseTriple(f, v); }},
      {"--translation-bounds", [&](auto& f, auto& v) { o.translation_bounds = ParseTriple(f, v); }},
      {"--max-rot-deg", [&](auto& f, auto& v) { o.max_rot_deg = ParsePositive(f, v); }},
      {"--max-trans-m", [&](auto& f, auto& v) { o.max_trans_m = ParsePositive(f, v); }},
      {"--max-pairs",
       [&](auto& f, auto& v) { options.max_pairs = static_cast<int>(ParseInteger(f, v, 1)); }},
      {"--data-root", [&](auto&, auto& v) { options.data_root = v; }},
      {"--scaling", [&](auto&, auto& v) { options.scaling_datasets = SplitList(v); }},
      {"--synthetic",
       [&](auto& f, auto& v) {
         options.synthetic_pairs = static_cast<int>(ParseInteger(f, v, 1));
       }},
  };

  for (int i = 1; i < argc; ++i) {
    std::string flag = argv[i];
    if (flag == "--quick") {
      options.quick = true;
      continue;
    }
    if (flag == "--scaling-only") {
      options.scaling_only = true;
      continue;
    }
    if (flag == "--auto-settings") {
      o.automatic_settings = true;
      continue;
    }
    if (flag == "--no-retry") {
      o.retry_when_doubtful = false;
      continue;
    }
    if (flag == "--help" || flag == "-h") {
      options.help = true;
      return options;
    }
    std::string value;
    const size_t equals = flag.find('=');
    if (equals != std::string::npos) {
      value = flag.substr(equals + 1);
      flag = flag.substr(0, equals);
    }
    const auto handler = with_value.find(flag);
    if (handler == with_value.end()) throw UsageError("unknown option '" + flag + "'");
    if (equals == std::string::npos) {
      if (i + 1 >= argc) throw UsageError(flag + ": missing value");
      value = argv[++i];
    }
    handler->second(flag, value);
  }

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
