// boicp: BO-ICP point-cloud registration and map building from the command line.

#include <iostream>
#include <map>

#include "commands.hpp"

int main(int argc, char** argv) {
  CLI::App app{"boicp: globally initialised ICP registration (BO-ICP) and map building"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "boicp " BOICP_VERSION);
  std::map<CLI::App*, boicp::cli::CommandRunner> runners;
  auto add = [&](CLI::App* sub, boicp::cli::CommandRunner run) { runners[sub] = std::move(run); };

  CLI::App* reg = app.add_subcommand("register", "Register one pair of scans locally (BO-ICP)");
  add(reg, boicp::cli::AddRegisterCommand(*reg));
  CLI::App* demo = app.add_subcommand("demo-data", "Write a generated demo pair or sequence");
  add(demo, boicp::cli::AddDemoDataCommand(*demo));
  CLI::App* map =
      app.add_subcommand("map", "Build a map from a scan folder or bag locally (no daemon)");
  add(map, boicp::cli::AddMapCommand(*map));
  CLI::App* preview = app.add_subcommand("preview", "Draw a top-down PNG of an OctoMap");
  add(preview, boicp::cli::AddPreviewCommand(*preview));
  CLI::App* merge = app.add_subcommand("merge", "Build the map of a sharded `map` run");
  add(merge, boicp::cli::AddMergeCommand(*merge));
  CLI::App* info = app.add_subcommand("info", "List a bag's topics, types, counts and duration");
  add(info, boicp::cli::AddInfoCommand(*info));
  CLI::App* eval =
      app.add_subcommand("eval", "Score a map's trajectory and pairs against a reference");
  add(eval, boicp::cli::AddEvalCommand(*eval));
#ifdef BOICP_WITH_REMOTE_COMMANDS  // talking to boicpd
  CLI::App* submit =
      app.add_subcommand("submit", "Upload a scan folder or bag and submit a job to boicpd");
  add(submit, boicp::cli::AddSubmitCommand(*submit));
  CLI::App* watch = app.add_subcommand("watch", "Follow a job to its end (exit 0 if it succeeded)");
  add(watch, boicp::cli::AddWatchCommand(*watch));
  CLI::App* jobs = app.add_subcommand("jobs", "List the daemon's jobs, newest first");
  add(jobs, boicp::cli::AddJobsCommand(*jobs));
  CLI::App* show = app.add_subcommand("show", "Show a job and its per-pair results");
  add(show, boicp::cli::AddShowCommand(*show));
  CLI::App* cancel = app.add_subcommand("cancel", "Cancel a queued or running job");
  add(cancel, boicp::cli::AddCancelCommand(*cancel));
  CLI::App* remove = app.add_subcommand("delete", "Delete a finished job and its outputs");
  add(remove, boicp::cli::AddDeleteCommand(*remove));
  CLI::App* exporter = app.add_subcommand("export", "Download a finished job's map or trajectory");
  add(exporter, boicp::cli::AddExportCommand(*exporter));
  CLI::App* health = app.add_subcommand("health", "Check that the daemon is serving");
  add(health, boicp::cli::AddHealthCommand(*health));
#endif

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? boicp::cli::kOk : boicp::cli::kBadInput;
  }
  for (auto& [sub, run] : runners) {
    if (sub->parsed()) return run();
  }
  return boicp::cli::kBadInput;
}
