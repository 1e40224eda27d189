#include "summary.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <sstream>

#include "boicp/util/percentile.hpp"
#include "methods.hpp"

namespace boicp::bench {
namespace {

std::string Format(const char* format, double value) {
  if (!std::isfinite(value)) return "-";
  char text[64];
  std::snprintf(text, sizeof(text), format, value);
  return text;
}

double Mean(const std::vector<double>& values) {
  if (values.empty()) return NAN;
  double sum = 0.0;
  for (double v : values) sum += v;
  return sum / static_cast<double>(values.size());
}

// Least-squares slope of log y against log x: the growth exponent.
double LogLogSlope(const std::vector<double>& x, const std::vector<double>& y) {
  std::vector<double> lx, ly;
  for (size_t i = 0; i < x.size(); ++i) {
    if (x[i] > 0.0 && y[i] > 0.0) {
      lx.push_back(std::log(x[i]));
      ly.push_back(std::log(y[i]));
    }
  }
  if (lx.size() < 2) return NAN;
  const double mx = Mean(lx), my = Mean(ly);
  double sxy = 0.0, sxx = 0.0;
  for (size_t i = 0; i < lx.size(); ++i) {
    sxy += (lx[i] - mx) * (ly[i] - my);
    sxx += (lx[i] - mx) * (lx[i] - mx);
  }
  return sxx > 0.0 ? sxy / sxx : NAN;
}

void DatasetTable(std::ostringstream& out, const std::string& dataset,
                  const std::vector<ResultRow>& rows) {
  out << "| method | pairs | median wall s | mean wall s | median rot deg | mean rot deg | "
         "median trans m | mean trans m | success | median confidence | median first search s "
         "| retried | retry s |\n"
         "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n";
  for (const std::string& method : MethodNames()) {
    std::vector<double> wall, first_search, rot, trans, confidence;
    int pairs = 0, successes = 0, errors = 0, retried = 0;
    double retry_s = 0.0;
    for (const ResultRow& r : rows) {
      if (r.experiment != "suite" || r.dataset != dataset || r.method != method) continue;
      ++pairs;
      successes += r.success ? 1 : 0;
      wall.push_back(r.wall_s);
      first_search.push_back(r.wall_s - r.retry_s);
      retried += r.attempts > 1 ? 1 : 0;
      retry_s += r.retry_s;
      if (!r.error.empty()) {
        ++errors;
        continue;
      }
      rot.push_back(r.rot_err_deg);
      trans.push_back(r.trans_err_m);
      if (r.confidence) confidence.push_back(*r.confidence);
    }
    if (pairs == 0) continue;
    char success[64];
    std::snprintf(success, sizeof(success), "%d/%d (%.0f%%)%s", successes, pairs,
                  100.0 * successes / pairs,
                  errors > 0 ? (", " + std::to_string(errors) + " threw").c_str() : "");
    out << "| " << method << " | " << pairs << " | " << Format("%.2f", Median(wall)) << " | "
        << Format("%.2f", Mean(wall)) << " | " << Format("%.3g", Median(rot)) << " | "
        << Format("%.3g", Mean(rot)) << " | " << Format("%.3g", Median(trans)) << " | "
        << Format("%.3g", Mean(trans)) << " | " << success << " | "
        << Format("%.2f", Median(confidence)) << " | " << Format("%.2f", Median(first_search))
        << " | " << retried << " | " << Format("%.1f", retry_s) << " |\n";
  }
}

void ScalingSection(std::ostringstream& out, const RunInfo& info,
                    const std::vector<ResultRow>& rows) {
  std::vector<const ResultRow*> scaling;
  for (const ResultRow& r : rows) {
    if (r.experiment != "suite") scaling.push_back(&r);
  }
  if (scaling.empty()) return;
  out << "\n## Scaling of bo-C\n\n"
      << info.scaling_line << ".\n\n"
      << "`icp s` is the time spent inside the ICP evaluations (timed between core's stop poll "
         "before and progress report after each one); `model s` is the rest after the first "
         "evaluation began, less the final refinement: GP fits, EI maximisation, confidence "
         "scans.\n\n"
      << "| experiment | dataset | voxel m | N | source pts | target pts | evaluations | wall s | "
         "icp s | model s | rot deg | trans m |\n"
      << "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n";
  for (const ResultRow* r : scaling) {
    out << "| " << r->experiment << " | " << r->dataset << " | " << Format("%.3g", r->voxel)
        << " | " << (r->iterations ? std::to_string(*r->iterations) : "-") << " | "
        << r->source_points << " | " << r->target_points << " | " << r->evaluations << " | "
        << Format("%.2f", r->wall_s) << " | " << Format("%.2f", r->icp_s.value_or(NAN)) << " | "
        << Format("%.2f", r->model_s.value_or(NAN)) << " | " << Format("%.3g", r->rot_err_deg)
        << " | " << Format("%.3g", r->trans_err_m) << " |\n";
  }

  // Growth exponents per dataset: what the algorithm predicts is about 1 for
  // ICP time against points (fixed evaluations) and against evaluations, and
  // 3 or more for the surrogate against samples per stage.
  std::vector<std::string> datasets;
  for (const ResultRow* r : scaling) {
    if (std::find(datasets.begin(), datasets.end(), r->dataset) == datasets.end()) {
      datasets.push_back(r->dataset);
    }
  }
  out << "\nLog-log slopes (growth exponents):\n\n";
  for (const std::string& dataset : datasets) {
    auto series = [&](const std::string& experiment, auto x_of, auto y_of) {
      std::vector<double> x, y;
      for (const ResultRow* r : scaling) {
        if (r->dataset != dataset || r->experiment != experiment || !r->error.empty()) continue;
        x.push_back(x_of(*r));
        y.push_back(y_of(*r));
      }
      return Format("%.2f", LogLogSlope(x, y));
    };
    auto points = [](const ResultRow& r) { return static_cast<double>(r.source_points); };
    // Nested bo-C evaluates N_r + N samples in each of its two stages.
    auto samples = [](const ResultRow& r) { return r.evaluations / 2.0; };
    auto evaluations = [](const ResultRow& r) { return static_cast<double>(r.evaluations); };
    auto wall = [](const ResultRow& r) { return r.wall_s; };
    auto icp = [](const ResultRow& r) { return r.icp_s.value_or(NAN); };
    auto model = [](const ResultRow& r) { return r.model_s.value_or(NAN); };
    out << "- " << dataset << ": wall vs source points " << series("scaling-voxel", points, wall)
        << " (2000-point evaluations), " << series("scaling-voxel-all", points, wall)
        << " (all points; icp s " << series("scaling-voxel-all", points, icp)
        << "); icp s vs evaluations " << series("scaling-iterations", evaluations, icp)
        << "; model s vs samples per stage " << series("scaling-iterations", samples, model)
        << "; wall vs samples per stage " << series("scaling-iterations", samples, wall) << ".\n";
  }
}

}  // namespace

std::string FormatRunConditions(const RunInfo& info) {
  std::ostringstream out;
  out << "- Machine: " << info.machine.logical_cores << " logical cores (nproc), CPU "
      << info.machine.cpu_model << ", load average at start " << info.machine.load_average
      << "; Open3D " << info.machine.open3d_version << "\n"
      << "- Thread budget: " << info.threads
      << " for every method (BO-ICP's concurrent ICP runs and acquisition, the pyramid's grid "
         "scoring, and "
         "Open3D through omp_set_num_threads and OMP_NUM_THREADS set before its first call); "
         "OMP_WAIT_POLICY="
      << (std::getenv("OMP_WAIT_POLICY") ? std::getenv("OMP_WAIT_POLICY") : "unset") << "\n"
      << "- Seeds: base seed " << info.seed
      << "; each pair's perturbation and method seed derive from it, the dataset name and the "
         "pair index (the `seed` column)\n"
      << "- Mode: "
      << (info.quick ? "--quick (smoke-test budgets; timings not meaningful)" : "standard") << "\n"
      << "- Command: `" << info.command_line << "`\n"
      << "- Started (UTC): " << info.started_utc << "\n\n"
      << "Datasets (table in bench/dataset_table.cpp, overridable by flags):\n\n";
  for (const DatasetSettings& d : info.datasets) out << "- " << DescribeSettings(d) << "\n";
  out << "\nMethods:\n\n";
  for (const std::string& line : info.method_lines) out << "- " << line << "\n";
  return out.str();
}

std::string FormatSummary(const RunInfo& info, const std::vector<ResultRow>& rows) {
  std::ostringstream out;
  out << "# boicp-bench results\n\n" << FormatRunConditions(info);
  char wall[64];
  std::snprintf(wall, sizeof(wall), "%.1f", info.wall_s);
  out << "\nTotal wall time of the run: " << wall << " s; load average at the end "
      << info.load_average_end << " (other jobs share this machine: read timings with it).\n";
  out << "Errors are against the reference with the perturbation folded in; success needs both "
         "under the dataset's thresholds. Medians and means leave out runs that threw.\n";
  for (const DatasetSettings& d : info.datasets) {
    out << "\n## " << d.name << "\n\n";
    DatasetTable(out, d.name, rows);
  }
  ScalingSection(out, info, rows);
  return out.str();
}

}  // namespace boicp::bench
