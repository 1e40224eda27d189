// icp-identity: plain ICP started from the identity, the baseline that shows
// how far the perturbation is outside ICP's basin.

#include "methods.hpp"
#include "shared_stages.hpp"

namespace boicp::bench {

MethodOutput RunIcpFromIdentity(const MethodInput& input) {
  const BoIcpConfig config = DatasetBoConfig("C", input);
  const PreparedPair pair = PreparePair(input.source, input.target, config);
  const Transform coarse = SearchIcp(Transform::Identity(), pair, config);
  MethodOutput output;
  output.transform = RefineCoarseToFine(coarse, pair, config);
  output.evaluations = 1;
  output.source_points = pair.search_source.size();
  output.target_points = pair.search_target.size();
  output.voxel = config.voxel;
  return output;
}

}  // namespace boicp::bench
