// `boicp jobs`: the daemon's jobs, newest first, as a table or JSON.

#include <cstdio>
#include <ctime>
#include <iostream>

#include "commands.hpp"
#include "printable_text.hpp"
#include "remote_json.hpp"
#include "remote_options.hpp"

namespace boicp::cli {
namespace {

struct JobsFlags {
  RemoteFlags remote;
  int limit = 50;
  bool json = false;
};

// "2026-12-01 10:33" in UTC; "-" for 0 (not yet).
std::string FormatTime(double unix_seconds) {
  if (unix_seconds <= 0.0) return "-";
  const std::time_t t = static_cast<std::time_t>(unix_seconds);
  std::tm utc{};
  gmtime_r(&t, &utc);
  char text[32];
  std::strftime(text, sizeof text, "%Y-%m-%d %H:%M", &utc);
  return text;
}

std::vector<v1::Job> FetchJobs(rpc::MapBuilderClient& client, int limit) {
  std::vector<v1::Job> jobs;
  std::string token;
  do {
    const uint32_t page = limit > 0 ? static_cast<uint32_t>(std::min(limit, 500)) : 500;
    const v1::ListJobsResponse response = client.ListJobs(page, token);
    for (const v1::Job& job : response.jobs()) {
      if (limit > 0 && static_cast<int>(jobs.size()) >= limit) break;
      jobs.push_back(job);
    }
    token = response.next_page_token();
  } while (!token.empty() && (limit <= 0 || static_cast<int>(jobs.size()) < limit));
  return jobs;
}

void PrintTable(const std::vector<v1::Job>& jobs) {
  std::printf("%-36s  %-9s  %-11s  %-11s  %5s  %-16s  %s\n", "JOB", "STATE", "STAGE", "PAIRS",
              "SCANS", "CREATED (UTC)", "LABEL");
  for (const v1::Job& job : jobs) {
    const std::string pairs =
        std::to_string(job.pairs_done()) + "/" + std::to_string(job.pairs_total());
    std::printf("%-36s  %-9s  %-11s  %-11s  %5u  %-16s  %s\n", job.job_id().c_str(),
                rpc::JobStateName(job.state()).c_str(), PrintableText(job.stage()).c_str(),
                pairs.c_str(), job.num_scans(), FormatTime(job.created_at()).c_str(),
                PrintableText(job.label()).c_str());
  }
}

}  // namespace

CommandRunner AddJobsCommand(CLI::App& app) {
  auto flags = std::make_shared<JobsFlags>();
  app.add_option("--limit", flags->limit, "Show at most this many jobs (0 = all)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  app.add_flag("--json", flags->json, "Print one JSON object {\"jobs\": [...]} instead");
  AddRemoteOptions(app, flags->remote);
  return [flags] {
    return RunRemote("jobs", flags->remote, [&] {
      Daemon daemon = ConnectToDaemon(flags->remote);
      const std::vector<v1::Job> jobs = FetchJobs(*daemon.client, flags->limit);
      if (flags->json) {
        nlohmann::json list = nlohmann::json::array();
        for (const v1::Job& job : jobs) list.push_back(JobToJson(job));
        std::cout << nlohmann::json{{"jobs", list}}.dump() << std::endl;
      } else {
        PrintTable(jobs);
      }
      return kOk;
    });
  };
}

}  // namespace boicp::cli
