// A ROS 2 bag that rosbag2 split into several storage files (NAME_0.db3,
// NAME_1.db3, ... beside one metadata.yaml, by size or duration), read as
// one bag: its topics' counts added up, its messages merged in log-time
// order, each read from the file that holds it.

#include <algorithm>
#include <map>
#include <optional>
#include <utility>

#include "bag_readers.hpp"
#include "boicp/util/types.hpp"

namespace boicp::io_detail {
namespace {

class SplitBag final : public BagReader {
 public:
  SplitBag(std::string folder, std::vector<std::unique_ptr<BagReader>> parts)
      : folder_(std::move(folder)), parts_(std::move(parts)) {}

  const std::string& path() const override { return folder_; }
  BagStorage storage() const override { return parts_.front()->storage(); }
  MessageEncoding encoding() const override { return parts_.front()->encoding(); }

  std::vector<BagTopic> Topics() override {
    std::map<std::string, BagTopic> by_name;
    for (const auto& part : parts_) {
      for (const BagTopic& topic : part->Topics()) {
        auto [it, added] = by_name.emplace(topic.name, topic);
        if (added) continue;
        if (it->second.type != topic.type) {
          throw InputError(part->path() + ": topic " + topic.name + " holds " + topic.type +
                           ", but " + it->second.type + " in an earlier file of " + folder_);
        }
        it->second.messages += topic.messages;
      }
    }
    std::vector<BagTopic> topics;
    for (auto& entry : by_name) topics.push_back(std::move(entry.second));
    return topics;
  }

  std::pair<int64_t, int64_t> TimeRange() override {
    std::optional<std::pair<int64_t, int64_t>> range;
    for (const auto& part : parts_) {
      const std::pair<int64_t, int64_t> span = part->TimeRange();
      if (span == std::make_pair(int64_t{0}, int64_t{0})) continue;  // no message
      range = range ? std::make_pair(std::min(range->first, span.first),
                                     std::max(range->second, span.second))
                    : span;
    }
    return range.value_or(std::make_pair(int64_t{0}, int64_t{0}));
  }

  // Each part's messages in its own order, then a stable merge by log time,
  // so that ties keep the files' order.
  std::vector<BagMessageRef> Messages(const std::string& topic) override {
    std::vector<BagMessageRef> messages;
    for (uint32_t file = 0; file < parts_.size(); ++file) {
      for (BagMessageRef message : parts_[file]->Messages(topic)) {
        message.file = file;
        messages.push_back(message);
      }
    }
    std::stable_sort(messages.begin(), messages.end(),
                     [](const BagMessageRef& a, const BagMessageRef& b) {
                       return a.log_time_ns < b.log_time_ns;
                     });
    return messages;
  }

  std::vector<uint8_t> Read(const BagMessageRef& message) override {
    if (message.file >= parts_.size()) {
      throw InputError(folder_ + ": no storage file " + std::to_string(message.file) + " (it has " +
                       std::to_string(parts_.size()) + ")");
    }
    return parts_[message.file]->Read(message);
  }

 private:
  std::string folder_;
  std::vector<std::unique_ptr<BagReader>> parts_;
};

}  // namespace

std::unique_ptr<BagReader> OpenSplitBag(const std::string& folder,
                                        std::vector<std::unique_ptr<BagReader>> parts) {
  if (parts.empty()) throw InputError(folder + ": no storage file");
  return std::make_unique<SplitBag>(folder, std::move(parts));
}

}  // namespace boicp::io_detail
