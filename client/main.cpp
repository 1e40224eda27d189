// boicp: BO-ICP point-cloud registration and map building from the command line.

#include <iostream>
#include <map>

#include "commands.hpp"

int main(int argc, char** argv) {
  CLI::App app{"boicp: globally initialised ICP registration (BO-ICP) and map building"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "boicp 0.1.0");
  std::map<CLI::App*, boicp::cli::CommandRunner> runners;
  auto add = [&](CLI::App* sub, boicp::cli::CommandRunner run) { runners[sub] = std::move(run); };

  CLI::App* reg = app.add_subcommand("register", "Register one pair of scans locally (BO-ICP)");
  add(reg, boicp::cli::AddRegisterCommand(*reg));
  CLI::App* demo = app.add_subcommand("demo-data", "Write a generated demo pair or sequence");
  add(demo, boicp::cli::AddDemoDataCommand(*demo));

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
