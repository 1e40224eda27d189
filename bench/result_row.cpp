#include "result_row.hpp"

#include <cmath>
#include <cstdio>
#include <sstream>

namespace boicp::bench {
namespace {

std::string Number(double value, const char* format = "%.6g") {
  if (!std::isfinite(value)) return "";
  char text[64];
  std::snprintf(text, sizeof(text), format, value);
  return text;
}

std::string Optional(const std::optional<double>& value) {
  return value ? Number(*value) : std::string();
}

std::string Text(const std::string& value) {
  if (value.find_first_of(",\"\n") == std::string::npos) return value;
  std::string quoted = "\"";
  for (char c : value) {
    if (c == '"') quoted += '"';
    quoted += c == '\n' ? ' ' : c;
  }
  return quoted + "\"";
}

std::string Features(const std::optional<ConfidenceFeatures>& f) {
  if (!f) return ",,,,,,,,,";
  return Number(f->fitness) + ',' + Number(f->rmse_ratio) + ',' + Number(f->margin) + ',' +
         Number(f->support) + ',' + Number(f->probability_better) + ',' +
         Number(f->resolution_deg) + ',' + Number(f->seen_through) + ',' +
         (f->margin_measured ? '1' : '0') + ',' + Number(f->constrained_share) + ',' +
         Number(f->slide_rival);
}

}  // namespace

std::string FormatResultsCsv(const std::vector<ResultRow>& rows) {
  std::ostringstream out;
  out << "experiment,dataset,source,target,method,threads,seed,perturb,voxel,iterations,"
         "source_points,target_points,evaluations,wall_s,rot_err_deg,trans_err_m,mean_p2p_m,"
         "overlap,success,confidence,icp_s,model_s,attempts,retry_s,fitness,rmse_ratio,margin,"
         "support,probability_better,resolution_deg,seen_through,margin_measured,constrained_share,"
         "slide_rival,answered_by,"
         "error\n";
  for (const ResultRow& r : rows) {
    out << r.experiment << ',' << Text(r.dataset) << ',' << Text(r.source) << ',' << Text(r.target)
        << ',' << r.method << ',' << r.threads << ',' << r.seed << ',' << r.perturb << ','
        << Number(r.voxel) << ',' << (r.iterations ? std::to_string(*r.iterations) : "") << ','
        << r.source_points << ',' << r.target_points << ',' << r.evaluations << ','
        << Number(r.wall_s, "%.4f") << ',' << Number(r.rot_err_deg) << ',' << Number(r.trans_err_m)
        << ',' << Number(r.mean_p2p_m) << ',' << Number(r.overlap, "%.4f") << ','
        << (r.success ? 1 : 0) << ',' << Optional(r.confidence) << ',' << Optional(r.icp_s) << ','
        << Optional(r.model_s) << ',' << r.attempts << ',' << Number(r.retry_s, "%.4f") << ','
        << Features(r.features) << ',' << r.answered_by << ',' << Text(r.error) << '\n';
  }
  return out.str();
}

std::string FormatAttemptsCsv(const std::vector<ResultRow>& rows) {
  std::ostringstream out;
  out << "experiment,dataset,source,target,method,attempt,kind,mode,fitness,rmse_ratio,margin,"
         "support,probability_better,resolution_deg,seen_through,margin_measured,constrained_share,"
         "slide_rival,confidence,"
         "success,kept\n";
  for (const ResultRow& r : rows) {
    for (size_t k = 0; k < r.attempt_rows.size(); ++k) {
      const AttemptRow& a = r.attempt_rows[k];
      out << r.experiment << ',' << Text(r.dataset) << ',' << Text(r.source) << ','
          << Text(r.target) << ',' << r.method << ',' << k << ',' << a.kind << ',' << a.mode << ','
          << Features(a.features) << ',' << Number(a.confidence) << ',' << (a.success ? 1 : 0)
          << ',' << (a.kept ? 1 : 0) << '\n';
    }
  }
  return out.str();
}

}  // namespace boicp::bench
