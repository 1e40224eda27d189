#pragma once
// Wall time measured on the steady clock, which no clock adjustment moves.

#include <chrono>

namespace boicp {

/// Seconds elapsed on the steady clock since `start`.
inline double SecondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace boicp
