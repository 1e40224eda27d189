#include "rpc_stats.hpp"

#include <algorithm>
#include <cmath>

namespace boicp::load {

double Percentile(std::vector<double>& samples, double q) {
  if (samples.empty()) return 0.0;
  std::sort(samples.begin(), samples.end());
  const auto rank = static_cast<size_t>(std::ceil(q * static_cast<double>(samples.size())));
  return samples[std::clamp<size_t>(rank, 1, samples.size()) - 1];
}

void RpcStats::AddUnexpectedError(const std::string& rpc, const std::string& what) {
  errors_.push_back(rpc + ": " + what);
}

void RpcStats::Merge(const RpcStats& other) {
  for (const auto& [rpc, samples] : other.latencies_ms_) {
    auto& mine = latencies_ms_[rpc];
    mine.insert(mine.end(), samples.begin(), samples.end());
  }
  errors_.insert(errors_.end(), other.errors_.begin(), other.errors_.end());
}

size_t RpcStats::Calls() const {
  size_t calls = errors_.size();
  for (const auto& entry : latencies_ms_) calls += entry.second.size();
  return calls;
}

std::map<std::string, LatencySummary> RpcStats::Summaries() const {
  std::map<std::string, LatencySummary> summaries;
  for (const auto& [rpc, samples] : latencies_ms_) {
    std::vector<double> sorted = samples;
    LatencySummary& s = summaries[rpc];
    s.calls = sorted.size();
    s.p50_ms = Percentile(sorted, 0.50);
    s.p99_ms = Percentile(sorted, 0.99);
    s.max_ms = sorted.empty() ? 0.0 : sorted.back();
  }
  return summaries;
}

}  // namespace boicp::load
