#include "boicp/mapping/pair_scheduler.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <deque>
#include <exception>
#include <memory>
#include <mutex>
#include <optional>
#include <set>
#include <string>

#include "boicp/mapping/batch_pair.hpp"
#include "boicp/mapping/loop_candidates.hpp"
#include "boicp/mapping/pair_scale.hpp"
#include "boicp/mapping/prepared_scan_cache.hpp"
#include "boicp/util/types.hpp"

namespace boicp {
namespace {

// How often the scheduling thread looks at stop requests and heartbeats
// while it waits for pairs.
constexpr auto kPollInterval = std::chrono::milliseconds(100);

// What a pair task hands back to the scheduling thread.
struct Completion {
  PairIndex pair;
  std::optional<PairResult> finished;  // set once stored
  bool stopped = false;                // Cancelled by a stop request or an abort
  std::exception_ptr error;            // set on failure
};

std::string MessageOf(const std::exception_ptr& error) {
  try {
    std::rethrow_exception(error);
  } catch (const std::exception& e) {
    return e.what();
  } catch (...) {
    return "unknown error";
  }
}

// Pairs of the plan a stored result can stand for: a fixed plan's own
// pairs; for keyframes, probes (a later scan onto an earlier keyframe) and
// the extras.
bool PlanUses(const PairingPlan& plan, const PairIndex& pair) {
  const auto listed = [&pair](const std::vector<PairIndex>& pairs) {
    return std::find(pairs.begin(), pairs.end(), pair) != pairs.end();
  };
  if (listed(plan.extras)) return true;
  return plan.keyframes ? pair.source > pair.target : listed(plan.chain);
}

// Why `result`'s pair ran, as the plan says (PairResult::kind).
void MarkKind(const PairingPlan& plan, PairResult& result) {
  const bool extra =
      std::find(plan.extras.begin(), plan.extras.end(), result.pair) != plan.extras.end();
  const bool bridge = plan.bridges.count(result.pair) != 0;
  const bool loop = !bridge && plan.found_priors.count(result.pair) != 0;
  result.kind = bridge ? "bridge" : loop ? "loop" : extra ? "extra" : "chain";
  const LoopFoundBy found_by =
      plan.places.count(result.pair) != 0 ? LoopFoundBy::kPlace : LoopFoundBy::kPoses;
  result.found_by = loop ? LoopFoundByName(found_by) : "";
}

// The batch's settings at each scale step its pairs use, with each scan
// prepared at them: the pairs of one step share their scans' preparation.
class ScaledPreparation {
 public:
  struct Level {
    BoIcpConfig config;
    std::unique_ptr<const RegistrationMethod> method;  // prepares every scan of this step
    std::unique_ptr<PreparedScanCache> prepared;
  };

  ScaledPreparation(const std::vector<ScanSource>& scans, const BoIcpConfig& config,
                    const BatchScale& scale, size_t capacity)
      : scans_(scans), config_(config), scale_(scale), capacity_(capacity) {}

  // The level of `pair`'s step, built on first use; it lives as long as this.
  // Thread-safe.
  Level& For(const PairIndex& pair) {
    const int step = PairScaleStep(scale_, pair);
    std::lock_guard<std::mutex> lock(mutex_);
    std::unique_ptr<Level>& level = levels_[step];
    if (!level) {
      auto built = std::make_unique<Level>();
      built->config = ScaledConfig(config_, scale_, step);
      built->method = CoreMethods().Create(built->config.method, built->config);
      built->prepared = std::make_unique<PreparedScanCache>(scans_, *built->method, capacity_);
      level = std::move(built);
    }
    return *level;
  }

 private:
  const std::vector<ScanSource>& scans_;
  const BoIcpConfig& config_;
  const BatchScale& scale_;
  const size_t capacity_;
  std::mutex mutex_;
  std::map<int, std::unique_ptr<Level>> levels_;  // by step; guarded by mutex_
};

class PairScheduler {
 public:
  PairScheduler(const std::vector<ScanSource>& scans, const BoIcpConfig& config,
                const BatchScale& scale, const PairingPlan& plan, PairStore& store,
                MapProgressSink& progress, const PairExecution& execution)
      : scans_(scans),
        plan_(plan),
        store_(store),
        progress_(progress),
        execution_(execution),
        num_scans_(static_cast<int>(scans.size())),
        // Pairs in flight share scans with the next pairs out of the queue.
        preparation_(scans, config, scale,
                     static_cast<size_t>(std::max(execution.max_in_flight, 1)) + 2) {}

  RegisteredPairs Run() {
    LoadStored();
    try {
      Schedule();
    } catch (...) {
      // Tasks refer to this scheduler: none may outlive it.
      aborting_ = true;
      WaitForTasks();
      throw;
    }
    if (StopRequested()) throw Cancelled();
    if (failure_) std::rethrow_exception(failure_);
    RegisteredPairs registered;
    registered.finished = std::move(finished_);
    registered.chain = planner_ ? planner_->ChainPairs() : plan_.chain;
    registered.reused = reused_;
    return registered;
  }

 private:
  bool StopRequested() const { return execution_.stop_requested && execution_.stop_requested(); }

  void LoadStored() {
    // Listing order: a fixed plan's own order; keyframe pairs in launch order.
    if (!plan_.keyframes) {
      std::vector<PairIndex> fixed = plan_.chain;
      fixed.insert(fixed.end(), plan_.extras.begin(), plan_.extras.end());
      for (size_t i = 0; i < fixed.size(); ++i) listing_order_[fixed[i]] = static_cast<int>(i);
    }
    for (PairResult& stored : store_.LoadFinished()) {
      if (!PlanUses(plan_, stored.pair)) continue;
      MarkKind(plan_, stored);
      finished_[stored.pair] = std::move(stored);
    }
    if (plan_.keyframes) {
      planner_.emplace(num_scans_, plan_.overlap_threshold);
      for (const auto& [pair, stored] : finished_) {
        planner_->Record(pair, ProbeOutcomeOf(stored));
        probed_sources_.insert(pair.source);
      }
    } else {
      for (const PairIndex& pair : plan_.chain) {
        if (finished_.count(pair) == 0) queue_.push_back(pair);
      }
    }
    for (const PairIndex& pair : plan_.extras) {
      if (finished_.count(pair) == 0) extras_queue_.push_back(pair);
    }
    next_order_ = static_cast<int>(finished_.size());
    reused_ = static_cast<int>(finished_.size());

    // Reused pairs in listing order, so a rerun reports them as the first run did.
    std::vector<const PairResult*> reused;
    for (const auto& entry : finished_) reused.push_back(&entry.second);
    std::stable_sort(reused.begin(), reused.end(), [this](const auto* a, const auto* b) {
      return ListingOrder(a->pair) < ListingOrder(b->pair);
    });
    PairCounts counts = Counts();
    counts.done = 0;
    counts.doubtful = 0;
    for (const PairResult* pair : reused) {
      ++counts.done;
      counts.doubtful += pair->doubtful;
      progress_.PairFinished(*pair, /*reused=*/true, counts);
    }
    progress_.RegistrationStarted(Counts());
  }

  int ListingOrder(const PairIndex& pair) const {
    const auto found = listing_order_.find(pair);
    return found != listing_order_.end() ? found->second : static_cast<int>(listing_order_.size());
  }

  PairCounts Counts() const {
    PairCounts counts;
    counts.done = static_cast<int>(finished_.size());
    counts.doubtful =
        static_cast<int>(std::count_if(finished_.begin(), finished_.end(),
                                       [](const auto& entry) { return entry.second.doubtful; }));
    if (planner_) {
      // Keyframe plans grow as they go: what ran or runs, plus one probe per
      // scan not probed yet.
      const int unprobed = std::max(0, num_scans_ - 1 - static_cast<int>(probed_sources_.size()));
      counts.total =
          static_cast<int>(finished_.size() + launched_.size() + extras_queue_.size()) + unprobed;
    } else {
      counts.total = static_cast<int>(plan_.chain.size() + plan_.extras.size());
    }
    return counts;
  }

  bool PlanComplete() const {
    if (planner_) return planner_->Done() && extras_queue_.empty();
    return queue_.empty() && extras_queue_.empty();
  }

  void Schedule() {
    std::unique_lock<std::mutex> lock(mutex_);
    for (;;) {
      if (!StopRequested() && !failure_) {
        lock.unlock();
        LaunchAvailable();
        lock.lock();
      }
      // A pair may have finished while the previous batch was absorbed: its
      // completion waits in completions_ and must be absorbed before the end.
      if (in_flight_ == 0 && completions_.empty() &&
          (PlanComplete() || StopRequested() || failure_)) {
        return;
      }
      changed_.wait_for(lock, kPollInterval, [this] { return !completions_.empty(); });
      std::deque<Completion> batch;
      batch.swap(completions_);
      lock.unlock();
      for (Completion& completion : batch) Absorb(std::move(completion));
      progress_.Heartbeat();
      lock.lock();
    }
  }

  // Hands pairs to the executor until this batch's share of it is used.
  // Keyframe probes get no extra queued slot: the next probe depends on results.
  void LaunchAvailable() {
    const int limit = std::max(execution_.max_in_flight, 1) + (planner_ ? 0 : 1);
    for (;;) {
      {
        std::lock_guard<std::mutex> lock(mutex_);
        if (in_flight_ >= limit) return;
      }
      const std::optional<PairIndex> next = NextPair();
      if (!next) return;
      Launch(*next);
    }
  }

  std::optional<PairIndex> NextPair() {
    if (!planner_) {
      std::deque<PairIndex>& queue = !queue_.empty() ? queue_ : extras_queue_;
      if (queue.empty()) return std::nullopt;
      const PairIndex pair = queue.front();
      queue.pop_front();
      return pair;
    }
    for (const PairIndex& probe : planner_->NextProbes(1)) {
      if (finished_.count(probe) != 0 || launched_.count(probe) != 0) continue;
      probed_sources_.insert(probe.source);
      return probe;
    }
    if (!extras_queue_.empty()) {
      const PairIndex pair = extras_queue_.front();
      extras_queue_.pop_front();
      return pair;
    }
    return std::nullopt;
  }

  void Launch(const PairIndex& pair) {
    launched_.insert(pair);
    const auto planned = listing_order_.find(pair);
    const int order = planned != listing_order_.end() ? planned->second : next_order_++;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      ++in_flight_;
    }
    try {
      execution_.submit([this, pair, order] { RunTask(pair, order); });
    } catch (...) {
      std::lock_guard<std::mutex> lock(mutex_);
      --in_flight_;
      throw;
    }
  }

  // On a worker thread. Stores the result before the scheduler reports it.
  void RunTask(const PairIndex& pair, int order) {
    Completion completion;
    completion.pair = pair;
    const auto stop = [this] { return aborting_ || StopRequested(); };
    if (stop()) {
      completion.stopped = true;
    } else {
      try {
        ScaledPreparation::Level& level = preparation_.For(pair);
        const auto prior = plan_.found_priors.find(pair);
        BoIcpConfig config = level.config;
        config.full_search_when_doubtful = prior == plan_.found_priors.end();
        PairResult result = RegisterBatchPair(scans_, pair, config, *level.prepared, stop,
                                              prior != plan_.found_priors.end()
                                                  ? std::optional<Transform>(prior->second)
                                                  : std::nullopt);
        MarkKind(plan_, result);
        store_.Save(order, result);
        completion.finished = std::move(result);
      } catch (const Cancelled&) {
        completion.stopped = true;
      } catch (...) {
        completion.error = std::current_exception();
      }
    }
    std::lock_guard<std::mutex> lock(mutex_);
    --in_flight_;
    completions_.push_back(std::move(completion));
    changed_.notify_all();
  }

  void Absorb(Completion completion) {
    launched_.erase(completion.pair);
    if (completion.error) {
      if (!failure_) {
        failure_ = completion.error;
        progress_.PairFailed(completion.pair, MessageOf(completion.error));
      }
      aborting_ = true;  // the run fails: the other pairs need not finish
      return;
    }
    if (!completion.finished) return;
    const PairResult& finished = finished_[completion.pair] = *completion.finished;
    if (planner_) planner_->Record(completion.pair, ProbeOutcomeOf(finished));
    progress_.PairFinished(finished, /*reused=*/false, Counts());
  }

  void WaitForTasks() {
    std::unique_lock<std::mutex> lock(mutex_);
    changed_.wait(lock, [this] { return in_flight_ == 0; });
  }

  const std::vector<ScanSource>& scans_;
  const PairingPlan& plan_;
  PairStore& store_;
  MapProgressSink& progress_;
  const PairExecution& execution_;
  const int num_scans_;
  ScaledPreparation preparation_;  // shared by the pair tasks

  // Used on the scheduling thread only.
  std::map<PairIndex, PairResult> finished_;
  std::optional<KeyframePlanner> planner_;
  std::deque<PairIndex> queue_;
  std::deque<PairIndex> extras_queue_;
  std::set<PairIndex> launched_;
  std::set<int> probed_sources_;
  std::map<PairIndex, int> listing_order_;
  int next_order_ = 0;
  int reused_ = 0;  // pairs loaded from the store
  std::exception_ptr failure_;

  std::atomic<bool> aborting_{false};
  std::mutex mutex_;
  std::condition_variable changed_;  // a pair finished
  // Guarded by mutex_.
  int in_flight_ = 0;
  std::deque<Completion> completions_;
};

}  // namespace

RegisteredPairs RegisterPlannedPairs(const std::vector<ScanSource>& scans,
                                     const BoIcpConfig& config, const BatchScale& scale,
                                     const PairingPlan& plan, PairStore& store,
                                     MapProgressSink& progress, const PairExecution& execution) {
  PairScheduler scheduler(scans, config, scale, plan, store, progress, execution);
  return scheduler.Run();
}

}  // namespace boicp
