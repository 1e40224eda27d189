#include "boicp/settings/rung_summary.hpp"

#include <algorithm>

namespace boicp::settings {
namespace {

// Every rung, cheapest first, with the word the closing count uses for it.
struct RungWord {
  Rung rung;
  const char* word;
};
constexpr RungWord kLadder[] = {{Rung::kPrior, "prior"},
                                {Rung::kFeatures, "features"},
                                {Rung::kShortSearch, "short"},
                                {Rung::kFullSearch, "full"},
                                {Rung::kRetry, "retry"}};

}  // namespace

std::optional<Rung> RungFromName(const std::string& name) {
  for (const RungWord& entry : kLadder) {
    if (RungName(entry.rung) == name) return entry.rung;
  }
  return std::nullopt;
}

std::string RungSummary(const std::vector<Rung>& answered_by) {
  std::string line;
  for (const RungWord& entry : kLadder) {
    const auto count = std::count(answered_by.begin(), answered_by.end(), entry.rung);
    if (count == 0) continue;
    line += (line.empty() ? "" : ", ") + std::to_string(count) + " " + entry.word;
  }
  return line;
}

}  // namespace boicp::settings
