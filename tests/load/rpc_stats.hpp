#pragma once
// Latencies and errors per RPC name. Each client keeps its own (no locks)
// and the run merges them once the clients have joined.

#include <cstdint>
#include <map>
#include <string>
#include <vector>

namespace boicp::load {

struct LatencySummary {
  size_t calls = 0;
  double p50_ms = 0.0, p99_ms = 0.0, max_ms = 0.0;
};

/// Nearest-rank percentile (`q` in [0, 1]) of `samples`, which it sorts.
/// 0 for an empty vector.
double Percentile(std::vector<double>& samples, double q);

class RpcStats {
 public:
  void AddLatency(const std::string& rpc, double ms) { latencies_ms_[rpc].push_back(ms); }
  /// An error nothing in the workload explains; any one fails the run.
  void AddUnexpectedError(const std::string& rpc, const std::string& what);
  void Merge(const RpcStats& other);

  size_t Calls() const;
  size_t UnexpectedErrors() const { return errors_.size(); }
  /// Every unexpected error as "rpc: what".
  const std::vector<std::string>& Errors() const { return errors_; }
  std::map<std::string, LatencySummary> Summaries() const;

 private:
  std::map<std::string, std::vector<double>> latencies_ms_;
  std::vector<std::string> errors_;
};

}  // namespace boicp::load
