// boicp_load: the daemon under 20 concurrent clients. Starts boicpd on a
// free loopback port, runs the load, prints the figures (and writes them to
// --out), and exits 1 when a check fails. The ctest runs it briefly;
// docs/reliability.md, "Load", has a longer run.

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <iostream>

#include "load_report.hpp"

int main(int argc, char** argv) {
  using namespace boicp::load;
  LoadOptions options;
  CLI::App app("Load test of boicpd: concurrent clients uploading scans and submitting batches");
  AddLoadOptions(app, options);
  CLI11_PARSE(app, argc, argv);
  try {
    ValidateLoadOptions(options);
  } catch (const std::invalid_argument& e) {
    std::cerr << "boicp_load: " << e.what() << "\n";
    return 2;
  }

  namespace fs = std::filesystem;
  const fs::path work_dir =
      options.work_dir.empty()
          ? fs::temp_directory_path() / ("boicp_load_" + std::to_string(::getpid()))
          : fs::path(options.work_dir);
  LoadFigures figures;
  std::vector<std::string> problems;
  try {
    fs::create_directories(work_dir);
    figures = RunLoad(options, work_dir.string());
    problems = CheckFigures(figures, options);
  } catch (const std::exception& e) {
    std::cerr << "boicp_load: " << e.what() << "\n(work folder: " << work_dir << ")\n";
    return 1;
  }

  WriteFigures(std::cout, figures, options, problems);
  if (!options.out.empty()) {
    std::ofstream out(options.out);
    WriteFigures(out, figures, options, problems);
    if (!out) {
      std::cerr << "boicp_load: cannot write " << options.out << "\n";
      return 1;
    }
  }
  if (!problems.empty()) {
    std::cerr << "boicp_load: FAILED; daemon log and data kept in " << work_dir << "\n";
    return 1;
  }
  if (!options.keep_work_dir) fs::remove_all(work_dir);
  return 0;
}
