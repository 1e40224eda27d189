// The shortest correct use of the library: two scans, no initial guess, one
// answer and whether it can be trusted.
//
//   register_pair SOURCE TARGET
//
// SOURCE and TARGET are point clouds in their sensor frames (.pcd, .ply,
// .xyz or KITTI .bin). Prints T_target_source (p_target = T * p_source,
// metres) and its confidence. Exits 0 for a trusted answer, 1 for a doubtful
// one and 2 for bad input.

#include <exception>
#include <iostream>

#include "boicp/io/point_cloud_io.hpp"
#include "boicp/registration/bo_icp.hpp"

int main(int argc, char** argv) {
  if (argc != 3) {
    std::cerr << "usage: register_pair SOURCE TARGET\n";
    return 2;
  }
  try {
    const boicp::Points source = boicp::LoadPointCloud(argv[1]).points;
    const boicp::Points target = boicp::LoadPointCloud(argv[2]).points;
    // The default config chooses its voxel, search box and thresholds from
    // the two clouds, and climbs the ladder until an answer is trusted.
    const boicp::RegistrationResult result =
        boicp::RegisterPair(source, target, boicp::BoIcpConfig{});
    std::cout << "T_target_source =\n"
              << result.transform << "\nconfidence " << result.confidence << " ("
              << (result.doubtful ? "doubtful" : "trusted") << "), answered by "
              << boicp::RungName(result.answered_by) << "\n";
    return result.doubtful ? 1 : 0;
  } catch (const std::exception& error) {
    std::cerr << "register_pair: " << error.what() << "\n";
    return 2;
  }
}
