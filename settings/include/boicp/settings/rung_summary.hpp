#pragma once
// Which rung of the escalation ladder answered a pair, as the front ends
// read it back and count it (`boicp map`, `merge` and `show` close with the
// count).

#include <optional>
#include <string>
#include <vector>

#include "boicp/registration/bo_icp.hpp"

namespace boicp::settings {

/// The rung RungName calls `name`; nullopt for any other word.
std::optional<Rung> RungFromName(const std::string& name);

/// How many of `answered_by` each rung gave, in ladder order, rungs that
/// gave none left out: "31 prior, 5 features, 2 short, 1 full, 1 retry"
/// (short and full are the searches). "" when there are none.
std::string RungSummary(const std::vector<Rung>& answered_by);

}  // namespace boicp::settings
