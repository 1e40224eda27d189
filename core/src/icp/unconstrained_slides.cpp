#include "boicp/icp/unconstrained_slides.hpp"

#include <algorithm>
#include <cmath>

#include <Eigen/Eigenvalues>

namespace boicp {

std::vector<FreeSlide> PrincipalSlides(const InformationMatrix& information,
                                       double inlier_distance) {
  const Eigen::Matrix3d slides = information.bottomRightCorner<3, 3>();
  const double matches = slides.trace();
  if (!(matches > 0.0)) return {};
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(slides);
  std::vector<FreeSlide> out;
  for (int i = 0; i < 3; ++i) {  // ascending
    const double across = std::max(solver.eigenvalues()(i), 0.0) / matches;
    const double extent = across > 0.0
                              ? std::min(inlier_distance / std::sqrt(across), kFreeSlideBound)
                              : kFreeSlideBound;
    out.push_back({solver.eigenvectors().col(i), across, extent});
  }
  return out;
}

std::vector<FreeSlide> UnconstrainedSlides(const InformationMatrix& information,
                                           double inlier_distance) {
  std::vector<FreeSlide> out = PrincipalSlides(information, inlier_distance);
  out.erase(
      std::remove_if(out.begin(), out.end(),
                     [](const FreeSlide& s) { return s.across_share >= kUnconstrainedShare; }),
      out.end());
  return out;
}

double ConstrainedShare(const InformationMatrix& information) {
  const std::vector<FreeSlide> slides = PrincipalSlides(information, 1.0);
  return slides.empty() ? 0.0 : slides.front().across_share;
}

}  // namespace boicp
