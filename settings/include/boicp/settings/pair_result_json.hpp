#pragma once
// A pair result as JSON, generated from PairResultFields(): pair files,
// pairs.json and the JSON of `boicp show` and `boicp results`.

#include <nlohmann/json.hpp>

#include "boicp/mapping/pair_result.hpp"

namespace boicp::settings {

/// The key ("source", "target") and every field `format` carries (one
/// PairResultFormat bit): transforms and information matrices as arrays of
/// rows, answered_by as RungName's word, an unknown value as null.
nlohmann::json PairResultToJson(const PairResult& result, PairResultFormat format);

/// One object per slide: {"axis": [x, y, z], "extent_m", "across_share"}.
nlohmann::json FreeSlidesToJson(const std::vector<FreeSlide>& slides);

/// One object of FreeSlidesToJson's, back. Throws InputError when malformed.
FreeSlide FreeSlideFromJson(const nlohmann::json& json);

/// The reverse of PairResultToJson. Throws InputError naming the first key
/// that is missing or malformed.
PairResult PairResultFromJson(const nlohmann::json& json, PairResultFormat format);

}  // namespace boicp::settings
