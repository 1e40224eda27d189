#include "boicp/icp/pair_information.hpp"

#include "boicp/icp/surface_normals.hpp"

namespace boicp {

InformationMatrix PlaneInformation(const Points& source, const NearestNeighborIndex& target,
                                   const Transform& T_target_source, double max_distance,
                                   double normal_radius) {
  InformationMatrix information = InformationMatrix::Zero();
  const double max_squared = max_distance * max_distance;
  for (const Point& p : TransformPoints(T_target_source, source)) {
    size_t match = 0;
    double squared = 0.0;
    if (!target.Nearest(p, max_squared, match, squared)) continue;
    const Point& q = target.points()[match];
    const Point n = SurfaceNormalAt(target, q, normal_radius);
    Eigen::Matrix<double, 6, 1> jacobian;
    jacobian << q.cross(n), n;
    information += jacobian * jacobian.transpose();
  }
  return information;
}

InformationMatrix MovedInformation(const InformationMatrix& information, const Point& offset) {
  InformationMatrix A = InformationMatrix::Identity();
  A.bottomLeftCorner<3, 3>() << 0.0, offset.z(), -offset.y(),  //
      -offset.z(), 0.0, offset.x(),                            //
      offset.y(), -offset.x(), 0.0;
  return A.transpose() * information * A;
}

}  // namespace boicp
