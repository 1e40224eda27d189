// `boicp info BAG`: what a bag holds (topics, types, message counts and
// duration), to pick --topic and --odometry-topic before a map.

#include <cstdio>
#include <iostream>

#include <nlohmann/json.hpp>

#include "boicp/io/bag_reader.hpp"
#include "boicp/util/types.hpp"
#include "commands.hpp"
#include "run_command.hpp"

namespace boicp::cli {
namespace {

using nlohmann::json;

struct InfoFlags {
  std::string path;
  bool json = false;
};

double Seconds(int64_t nanoseconds) { return static_cast<double>(nanoseconds) * 1e-9; }

json InfoJson(BagReader& bag) {
  const auto [first, last] = bag.TimeRange();
  json topics = json::array();
  for (const BagTopic& topic : bag.Topics()) {
    topics.push_back({{"name", topic.name}, {"type", topic.type}, {"messages", topic.messages}});
  }
  return {{"path", bag.path()},
          {"storage", BagStorageName(bag.storage())},
          {"start", Seconds(first)},
          {"duration", Seconds(last - first)},
          {"topics", topics}};
}

void PrintInfo(const json& info) {
  std::printf("%s: %s, %.3f s from %.3f\n", info["path"].get<std::string>().c_str(),
              info["storage"].get<std::string>().c_str(), info["duration"].get<double>(),
              info["start"].get<double>());
  for (const json& topic : info["topics"]) {
    std::printf("  %-32s %-36s %8llu messages\n", topic["name"].get<std::string>().c_str(),
                topic["type"].get<std::string>().c_str(),
                static_cast<unsigned long long>(topic["messages"].get<uint64_t>()));
  }
}

int RunInfo(const InfoFlags& flags) {
  const std::unique_ptr<BagReader> bag = OpenBag(flags.path);
  const json info = InfoJson(*bag);
  if (flags.json) {
    std::cout << info.dump() << std::endl;
  } else {
    PrintInfo(info);
  }
  return kOk;
}

}  // namespace

CommandRunner AddInfoCommand(CLI::App& app) {
  auto flags = std::make_shared<InfoFlags>();
  app.add_option("BAG", flags->path, "ROS 1 .bag, ROS 2 .mcap or .db3 file, or ROS 2 bag folder")
      ->required();
  app.add_flag("--json", flags->json,
               "One JSON object on stdout: path, storage, start, duration (s), topics [{name, "
               "type, messages}]");
  return [flags] { return RunCommand("info", [&] { return RunInfo(*flags); }); };
}

}  // namespace boicp::cli
