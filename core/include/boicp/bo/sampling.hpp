#pragma once
// Space-filling initial designs on the unit box.

#include <random>

#include <Eigen/Core>

namespace boicp {

/// n points in [0,1]^d, one in each of the n equal slices of every axis
/// (Latin hypercube), slices shuffled independently per axis. Reproducible for
/// a given rng state. Returns an n x d matrix.
Eigen::MatrixXd LatinHypercube(int n, int d, std::mt19937_64& rng);

/// Uniform double in [0, 1) from the top 53 bits of one draw. Used instead of
/// std::uniform_real_distribution, whose output differs between standard
/// libraries, so designs are identical on every platform.
double UniformUnit(std::mt19937_64& rng);

/// n independent uniform points in [0,1)^d (filled row by row); n x d.
Eigen::MatrixXd UniformPoints(int n, int d, std::mt19937_64& rng);

/// n rotations spread evenly over all rotations (a super-Fibonacci spiral on
/// the unit quaternions, Alexa 2022), all turned by one rotation drawn
/// uniformly from rng; as unit coordinates of their rotation vectors
/// (UnitFromRotation), n x 3.
Eigen::MatrixXd UniformRotations(int n, std::mt19937_64& rng);

}  // namespace boicp
