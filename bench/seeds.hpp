#pragma once
// Derived seeds: every random choice of a run follows from --seed, and a
// pair's draws do not depend on which other pairs or datasets were selected.

#include <cstdint>
#include <string>

namespace boicp::bench {

/// SplitMix64 finaliser of a combined with b: well-spread, platform-independent.
uint64_t MixSeed(uint64_t a, uint64_t b);

/// FNV-1a hash of a name, so a dataset's seeds depend on its name, not its
/// position on the command line.
uint64_t NameSeed(const std::string& name);

}  // namespace boicp::bench
