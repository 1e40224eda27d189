// _boicp: the compiled half of the Python package `boicp` (python/boicp/
// holds its public face). Settings come in as Python dicts keyed by setting
// name and results go out as the JSON the CLI prints, parsed by Python's
// json module, so every dict equals the CLI's output. The engine runs with
// the GIL released; Ctrl-C stops it (PythonInterrupt).

#include <chrono>
#include <filesystem>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "boicp/io/point_cloud_io.hpp"
#include "boicp/util/parallel_for.hpp"
#include "cloud_registration.hpp"
#include "local_map.hpp"
#include "named_settings.hpp"
#include "numpy_points.hpp"
#include "python_interrupt.hpp"
#include "python_progress.hpp"
#ifdef BOICP_WITH_REMOTE_COMMANDS
#include "boicp/rpc/map_builder_client.hpp"
#include "boicp/rpc/proto_convert.hpp"
#include "submit_request.hpp"
#endif

namespace boicp::python {
namespace {

namespace py = pybind11;
using nlohmann::json;

// A dict of settings as JSON (tuples become lists; numpy scalars and arrays
// their Python values).
json JsonOf(const py::dict& settings) {
  const py::cpp_function builtin([](const py::object& value) -> py::object {
    if (py::hasattr(value, "tolist")) return value.attr("tolist")();
    throw py::type_error("a setting's value must be a number, text, bool or sequence, not " +
                         py::str(py::type::of(value)).cast<std::string>());
  });
  return json::parse(py::module_::import("json")
                         .attr("dumps")(settings, py::arg("default") = builtin)
                         .cast<std::string>());
}

py::object PythonOf(const json& value) {
  return py::module_::import("json").attr("loads")(value.dump());
}

// Runs `work` without the GIL, stopping it on Ctrl-C or a callback's
// exception, which is then raised here.
template <typename Work>
void RunInterruptibly(PythonInterrupt& interrupt, Work work) {
  bool cancelled = false;
  {
    py::gil_scoped_release release;
    try {
      work();
    } catch (const Cancelled&) {
      cancelled = true;
    }
  }
  interrupt.RaiseIfRecorded();
  if (cancelled) throw std::runtime_error("stopped before it finished");
}

py::object RegisterClouds(const py::array& source_array, const py::array& target_array,
                          const py::dict& settings, const py::object& prior_array) {
  const ArrayPoints source(source_array, "source");
  const ArrayPoints target(target_array, "target");
  std::optional<Transform> prior;
  if (!prior_array.is_none()) prior = TransformFromArray(py::array(prior_array), "prior");
  settings::RequestedSettings requested =
      RegisterSettingsByName(JsonOf(settings), "boicp.register");
  // One registration alone on the machine: every core, as `boicp register`.
  if (!requested.threads) requested.threads = AvailableCores();
  const BoIcpConfig config = settings::ConfigFromSettings(requested);

  PythonInterrupt interrupt;
  json report;
  RunInterruptibly(interrupt, [&] {
    const cli::PairSettingsChoice chosen =
        cli::ChooseCloudPairSettings(source.span(), target.span(), config, CloudFormat::kAuto);
    RegistrationCallbacks callbacks;
    callbacks.stop_requested = [&interrupt] { return interrupt.Requested(); };
    report = cli::RegisterReportJson(
        cli::RegisterCloudPair(source.span(), target.span(), chosen, prior, callbacks), chosen);
  });
  return PythonOf(report);
}

py::array_t<double> ReadScan(const std::string& path, const std::string& format,
                             const std::string& intrinsics, const std::string& intrinsics_file,
                             double depth_scale, const std::vector<int>& invalid_depth,
                             uint64_t max_points) {
  LoadOptions options;
  options.format = ParseCloudFormat(format);
  if (!intrinsics.empty()) options.depth.intrinsics = ParseIntrinsics(intrinsics);
  if (!intrinsics_file.empty()) options.depth.intrinsics = ReadIntrinsicsFile(intrinsics_file);
  options.depth.depth_scale = depth_scale;
  options.depth.invalid_values.clear();
  for (int v : invalid_depth) {
    if (v < 0 || v > 65535) throw InputError("invalid_depth: values must be in 0..65535");
    options.depth.invalid_values.push_back(static_cast<uint16_t>(v));
  }
  options.max_points = max_points;
  LoadedCloud cloud;
  {
    py::gil_scoped_release release;
    cloud = LoadPointCloud(path, options);
  }
  return ArrayFromPoints(std::move(cloud.points));
}

py::object BuildMap(const std::string& folder, const std::string& out_dir, const py::dict& settings,
                    int threads, uint64_t max_fusion_mb, const py::object& progress) {
  if (out_dir.empty()) throw InputError("out_dir is required");
  if (threads < 0) throw InputError("threads: must be >= 0 (0 = every core)");
  if (threads == 0) threads = AvailableCores();
  const cli::MapSettings map_settings =
      MapSettingsByName(folder, JsonOf(settings), settings::kMap, "boicp.build_map");
  PythonInterrupt interrupt;
  PythonMapProgress sink(progress, interrupt);
  json summary;
  RunInterruptibly(interrupt, [&] {
    const auto start = std::chrono::steady_clock::now();
    cli::LocalRun run = cli::PrepareRun(map_settings);
    cli::ChooseMapRunSettings(run, threads, max_fusion_mb);
    cli::WriteRunManifest(run, out_dir);
    cli::LocalMapHooks hooks;
    hooks.progress = &sink;
    hooks.stop_requested = [&interrupt] { return interrupt.Requested(); };
    const cli::MapOutputSummary out = cli::BuildLocalMap(run, out_dir, threads, hooks);
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    summary = cli::MapSummaryJson(run, out, out_dir, seconds);
  });
  return PythonOf(summary);
}

#ifdef BOICP_WITH_REMOTE_COMMANDS
// The bytes each planned scan is uploaded as (rpc::ScanUploadBytes), read
// one at a time when asked, so that a bag's scans are never all in memory.
class PlannedScanBytes {
 public:
  explicit PlannedScanBytes(std::vector<ScanSource> scans) : scans_(std::move(scans)) {}

  py::bytes Read(size_t index) const {
    if (index >= scans_.size()) {
      throw py::index_error("scan " + std::to_string(index) + " of " +
                            std::to_string(scans_.size()));
    }
    std::string bytes;
    {
      py::gil_scoped_release release;
      bytes = rpc::ScanUploadBytes(scans_[index]);
    }
    return py::bytes(bytes);
  }
  size_t size() const { return scans_.size(); }

 private:
  std::vector<ScanSource> scans_;
};

// `scans`: a folder or a bag (str), or a sequence of scan files.
py::dict PlanSubmission(const py::object& scans, const py::dict& settings) {
  json by_name = JsonOf(settings);
  const std::string label = by_name.value("label", std::string());
  by_name.erase("label");
  const bool folder = py::isinstance<py::str>(scans);
  std::vector<std::string> files;
  if (!folder) {
    for (const py::handle& file : scans) files.push_back(py::str(file).cast<std::string>());
  }
  const cli::MapSettings map_settings =
      MapSettingsByName(folder ? scans.cast<std::string>() : std::string(), by_name,
                        settings::kSubmit, "boicp.client.submit");
  const cli::LocalRun run =
      folder ? cli::PrepareRun(map_settings) : cli::PrepareRun(map_settings, files);
  {
    py::gil_scoped_release release;
    CheckScansLoad(run.batch.scans, AvailableCores());
  }
  py::list uploads;
  for (const ScanSource& scan : run.batch.scans) {
    py::dict entry;
    entry["path"] = scan.path;
    entry["metadata"] = py::bytes(rpc::ScanMetadataOf(scan).SerializeAsString());
    uploads.append(entry);
  }
  py::dict out;
  // A list's label, unless given: the folder of its first file.
  const std::string default_label =
      folder ? std::string() : std::filesystem::path(files.front()).parent_path().string();
  out["request"] = py::bytes(
      cli::BuildSubmitRequest(run, label.empty() ? default_label : label).SerializeAsString());
  out["scans"] = uploads;
  out["read"] = PlannedScanBytes(run.batch.scans);
  out["description"] = run.description;
  return out;
}
#endif

}  // namespace

PYBIND11_MODULE(_boicp, m) {
  m.doc() = "The compiled half of the boicp package; use `import boicp`.";
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const InputError& e) {
      PyErr_SetString(PyExc_ValueError, e.what());
    } catch (const LimitExceeded& e) {
      PyErr_SetString(PyExc_ValueError, e.what());
    }
  });
  m.attr("__version__") = BOICP_VERSION;
  m.def("register_clouds", &RegisterClouds, py::arg("source"), py::arg("target"),
        py::arg("settings"), py::arg("prior"));
  m.def(
      "_reads_in_place",
      [](const py::array& points) { return ArrayPoints(points, "points").in_place(); },
      py::arg("points"), "Whether register reads `points` where they lie rather than from a copy.");
  m.def("read_scan", &ReadScan, py::arg("path"), py::arg("format"), py::arg("intrinsics"),
        py::arg("intrinsics_file"), py::arg("depth_scale"), py::arg("invalid_depth"),
        py::arg("max_points"));
  m.def("build_map", &BuildMap, py::arg("folder"), py::arg("out_dir"), py::arg("settings"),
        py::arg("threads"), py::arg("max_fusion_mb"), py::arg("progress"));
#ifdef BOICP_WITH_REMOTE_COMMANDS
  py::class_<PlannedScanBytes>(m, "PlannedScanBytes",
                               "read(i): the bytes planned scan i is uploaded as.")
      .def("__call__", &PlannedScanBytes::Read, py::arg("index"))
      .def("__len__", &PlannedScanBytes::size);
  m.def("plan_submission", &PlanSubmission, py::arg("scans"), py::arg("settings"),
        "The batch request, the scans' upload metadata and a reader of their bytes, as "
        "`boicp submit` would send them for `scans` (a folder or a bag, or a list of scan "
        "files) with `settings` (by name, as build_map takes them; 'label' too).");
#endif
}

}  // namespace boicp::python
