// icp-identity: plain ICP started from the identity, the baseline that shows
// how far the perturbation is outside ICP's basin.

#include "boicp/registration/refinement.hpp"
#include "methods.hpp"

namespace boicp::bench {

RegistrationResult RunIcpFromIdentity(const Points& source, const Points& target,
                                      const BoIcpConfig& config) {
  const PreparedPair pair = PreparePair(source, target, config);
  const Transform identity =
      CentredTransform(pair.source_centre, pair.target_centre, Transform::Identity());
  const Transform coarse =
      AlignPointToPoint(pair.search_source, pair.search_target, identity, SearchIcpOptions(config))
          .transform;
  RegistrationResult output;
  output.transform = UncentredTransform(pair.source_centre, pair.target_centre,
                                        RefineCoarseToFine({coarse}, pair, config).transform);
  output.evaluations = 1;
  output.source_points = pair.search_source.size();
  output.target_points = pair.search_target.size();
  output.config = config;
  return output;
}

}  // namespace boicp::bench
