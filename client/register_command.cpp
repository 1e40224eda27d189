// `boicp register`: one pair, locally, printing the transform (or JSON).

#include <cmath>
#include <cstdio>
#include <iomanip>
#include <iostream>
#include <optional>

#include "boicp/io/point_cloud_io.hpp"
#include "boicp/registration/bo_icp.hpp"
#include "boicp/settings/settings_flags.hpp"
#include "boicp/util/parallel_for.hpp"
#include "cli_parsing.hpp"
#include "cloud_registration.hpp"
#include "commands.hpp"
#include "run_command.hpp"

namespace boicp::cli {
namespace {

struct RegisterFlags {
  std::string source, target, format = "auto";
  std::string intrinsics, intrinsics_file, prior_file;
  std::vector<int> invalid_depth = {0, 65535};
  double depth_scale = 0.0;
  double scale_source = 1.0;
  settings::RequestedSettings settings;
  settings::FlagTexts setting_texts;
  bool json = false, quiet = false;
};

BoIcpConfig BuildConfig(const RegisterFlags& f) {
  settings::RequestedSettings given = f.settings;
  settings::ApplyFlagTexts(f.setting_texts, settings::kRegister, given);
  // One registration alone on the machine: every core, unless told otherwise.
  if (!given.threads) given.threads = AvailableCores();
  return settings::ConfigFromSettings(given);
}

LoadOptions BuildLoadOptions(const RegisterFlags& f) {
  LoadOptions options;
  options.format = ParseCloudFormat(f.format);
  if (!f.intrinsics.empty()) options.depth.intrinsics = ParseIntrinsics(f.intrinsics);
  if (!f.intrinsics_file.empty()) options.depth.intrinsics = ReadIntrinsicsFile(f.intrinsics_file);
  options.depth.depth_scale = f.depth_scale;
  options.depth.invalid_values.clear();
  for (int v : f.invalid_depth) {
    if (v < 0 || v > 65535) throw InputError("--invalid-depth: values must be in 0..65535");
    options.depth.invalid_values.push_back(static_cast<uint16_t>(v));
  }
  return options;
}

// Progress on stderr: one redrawn line on a terminal, a line per stage otherwise.
RegistrationCallbacks MakeProgressPrinter(bool quiet) {
  RegistrationCallbacks callbacks;
  if (quiet) return callbacks;
  const bool terminal = StderrIsTerminal();
  callbacks.progress = [terminal](const RegistrationProgress& p) {
    if (terminal) {
      std::fprintf(stderr, "\r%-11s %3d/%-3d best objective %.4f m   ", p.stage.c_str(), p.done,
                   p.total, p.best_objective);
      if (p.done == p.total) std::fputc('\n', stderr);
    } else if (p.done == p.total) {
      std::fprintf(stderr, "%s: %d evaluations, best objective %.4f m\n", p.stage.c_str(), p.total,
                   p.best_objective);
    }
  };
  return callbacks;
}

void PrintHuman(const RegistrationResult& r) {
  std::cout << "T_target_source (p_target = T * p_source):\n" << std::fixed << std::setprecision(6);
  for (int i = 0; i < 4; ++i) {
    for (int j = 0; j < 4; ++j) std::cout << (j ? " " : "  ") << std::setw(10) << r.transform(i, j);
    std::cout << "\n";
  }
  std::cout << std::setprecision(4) << "objective   " << r.objective << " m\n"
            << "fitness     " << r.fitness << "\n"
            << "inlier_rmse " << r.inlier_rmse << " m\n"
            << "confidence  " << r.confidence << (r.doubtful ? " (doubtful)" : "") << "\n"
            << "attempts    " << r.attempts.size() << "\n"
            << "answered_by " << RungName(r.answered_by) << "\n"
            << "evaluations " << r.evaluations << "\n"
            << "runtime     " << r.runtime_s << " s\n";
}

int RunRegister(const RegisterFlags& flags) {
  const BoIcpConfig config = BuildConfig(flags);
  const LoadOptions load = BuildLoadOptions(flags);
  if (!(flags.scale_source > 0.0) || !std::isfinite(flags.scale_source)) {
    throw InputError("--scale-source must be a positive number");
  }
  LoadedCloud source = LoadPointCloud(flags.source, load);
  if (flags.scale_source != 1.0) {
    for (Point& p : source.points) p *= flags.scale_source;
  }
  const LoadedCloud target = LoadPointCloud(flags.target, load);
  std::optional<Transform> prior;
  if (!flags.prior_file.empty()) prior = ReadTransformFile(flags.prior_file);
  const PairSettingsChoice settings =
      ChooseCloudPairSettings(source.points, target.points, config, source.format);
  const ChosenSettings& chosen = settings.chosen;
  if (!flags.quiet) {
    std::fprintf(stderr,
                 "loaded %zu source and %zu target points (%zu and %zu non-finite dropped)\n",
                 source.points.size(), target.points.size(), source.dropped_nonfinite,
                 target.dropped_nonfinite);
    std::fprintf(stderr, "%s\n",
                 DescribeSettings(settings.config, settings.auto_fields, chosen).c_str());
    if (chosen.far_returns[0] + chosen.far_returns[1] > 0) {
      std::fprintf(stderr,
                   "%zu source and %zu target points set aside as far returns when choosing "
                   "the settings (they stay in the scans)\n",
                   chosen.far_returns[0], chosen.far_returns[1]);
    }
  }
  const RegistrationResult result = RegisterCloudPair(source.points, target.points, settings, prior,
                                                      MakeProgressPrinter(flags.quiet));
  if (flags.json) {
    std::cout << RegisterReportJson(result, settings).dump() << std::endl;
  } else {
    PrintHuman(result);
  }
  return kOk;
}

}  // namespace

CommandRunner AddRegisterCommand(CLI::App& app) {
  auto flags = std::make_shared<RegisterFlags>();
  RegisterFlags& f = *flags;
  app.add_option("--source", f.source, "Source scan (moved onto the target)")->required();
  app.add_option("--target", f.target, "Target scan")->required();
  app.add_flag("--json", f.json, "Print one JSON object on stdout");
  app.add_flag("-q,--quiet", f.quiet, "No progress on stderr");
  app.add_option("--format", f.format, "auto, kitti, pcd, ply, xyz or depth")
      ->capture_default_str();
  app.add_option("--intrinsics", f.intrinsics, "Depth camera fx,fy,cx,cy (pixels)");
  app.add_option("--intrinsics-file", f.intrinsics_file, "File with fx fy cx cy or a 3x3 K");
  app.add_option("--depth-scale", f.depth_scale,
                 "Depth PNG units per metre (TUM 5000, 7-Scenes 1000)");
  app.add_option("--invalid-depth", f.invalid_depth, "Raw depth values meaning no data")
      ->delimiter(',')
      ->capture_default_str();
  app.add_option("--prior", f.prior_file, "Initial guess: file with a 4x4 or 3x4 T_target_source");
  app.add_option("--scale-source", f.scale_source,
                 "Multiply the source's coordinates by this first (0.001: millimetres to metres "
                 "when the target is in metres); the prior and the answer map the scaled source")
      ->capture_default_str();
  settings::AddSettingFlags(app, settings::kRegister, f.settings, f.setting_texts);
  return [flags] { return RunCommand("register", [&] { return RunRegister(*flags); }); };
}

}  // namespace boicp::cli
