#pragma once
// A pair result as boicp.v1.PairResult, generated from PairResultFields()
// (the fields marked kPairApi) by field name.

#include "boicp/mapping/pair_result.hpp"
#include "boicp/v1/map_builder.pb.h"

namespace boicp::rpc {

/// Sets the key and every kPairApi field of `out`; the scan ids are the caller's.
void PairResultToProto(const PairResult& result, ::boicp::v1::PairResult* out);

/// The reverse. Results stored before a field existed read as PairResult's
/// comments say: with no doubtful flag as confidence 1 and trusted, with no
/// answered_by as the full search (AnsweredBy). Throws InputError naming a
/// malformed field or a rung this build does not know.
PairResult PairResultFromProto(const ::boicp::v1::PairResult& message);

}  // namespace boicp::rpc
