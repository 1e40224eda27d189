#include "boicp/bo/sampling.hpp"

#include <cmath>
#include <cstdint>
#include <numeric>
#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "boicp/bo/kernel_inputs.hpp"

namespace boicp {
namespace {

// Unbiased integer in [0, bound) by rejection: draws below 2^64 mod bound would
// make the low residues slightly more likely, so they are redrawn.
uint64_t UniformIndex(uint64_t bound, std::mt19937_64& rng) {
  const uint64_t threshold = (0 - bound) % bound;
  for (;;) {
    const uint64_t r = rng();
    if (r >= threshold) return r % bound;
  }
}

// Fisher-Yates, written out because std::shuffle's sequence is library-specific.
std::vector<int> RandomPermutation(int n, std::mt19937_64& rng) {
  std::vector<int> p(static_cast<size_t>(n));
  std::iota(p.begin(), p.end(), 0);
  for (int i = n - 1; i > 0; --i) {
    const auto j = static_cast<int>(UniformIndex(static_cast<uint64_t>(i) + 1, rng));
    std::swap(p[static_cast<size_t>(i)], p[static_cast<size_t>(j)]);
  }
  return p;
}

void CheckShape(int n, int d, const char* what) {
  if (n < 0 || d < 0) {
    throw std::invalid_argument(std::string(what) + ": negative size " + std::to_string(n) + " x " +
                                std::to_string(d));
  }
}

constexpr double kTwoPi = 6.28318530717958647692;

// A uniform unit quaternion from three uniform numbers (Shoemake 1992).
Eigen::Quaterniond UniformQuaternion(std::mt19937_64& rng) {
  const double u1 = UniformUnit(rng), u2 = UniformUnit(rng), u3 = UniformUnit(rng);
  const double a = std::sqrt(1.0 - u1), b = std::sqrt(u1);
  return Eigen::Quaterniond(b * std::cos(kTwoPi * u3), a * std::sin(kTwoPi * u2),
                            a * std::cos(kTwoPi * u2), b * std::sin(kTwoPi * u3));
}

}  // namespace

double UniformUnit(std::mt19937_64& rng) { return static_cast<double>(rng() >> 11) * 0x1.0p-53; }

Eigen::MatrixXd UniformPoints(int n, int d, std::mt19937_64& rng) {
  CheckShape(n, d, "UniformPoints");
  Eigen::MatrixXd X(n, d);
  for (int i = 0; i < n; ++i) {
    for (int k = 0; k < d; ++k) X(i, k) = UniformUnit(rng);
  }
  return X;
}

Eigen::MatrixXd LatinHypercube(int n, int d, std::mt19937_64& rng) {
  CheckShape(n, d, "LatinHypercube");
  Eigen::MatrixXd X(n, d);
  for (int k = 0; k < d; ++k) {
    const std::vector<int> slice = RandomPermutation(n, rng);
    for (int i = 0; i < n; ++i) {
      X(i, k) = (slice[static_cast<size_t>(i)] + UniformUnit(rng)) / n;
    }
  }
  return X;
}

Eigen::MatrixXd UniformRotations(int n, std::mt19937_64& rng) {
  CheckShape(n, 3, "UniformRotations");
  // The spiral's two irrational turning rates (Alexa, "Super-Fibonacci
  // Spirals", CVPR 2022).
  const double phi = std::sqrt(2.0), psi = 1.533751168755204288118041;
  const Eigen::Quaterniond turn = UniformQuaternion(rng);
  Eigen::MatrixXd U(n, 3);
  for (int i = 0; i < n; ++i) {
    const double s = i + 0.5;
    const double r = std::sqrt(s / n), R = std::sqrt(1.0 - s / n);
    const double alpha = kTwoPi * s / phi, beta = kTwoPi * s / psi;
    const Eigen::Quaterniond q(R * std::cos(beta), r * std::sin(alpha), r * std::cos(alpha),
                               R * std::sin(beta));
    U.row(i) = UnitFromRotation((turn * q).toRotationMatrix()).transpose();
  }
  return U;
}

}  // namespace boicp
