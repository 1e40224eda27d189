#pragma once
// The registration problems of a run: reference pairs loaded with the core
// loaders, the source moved by a seeded random rigid perturbation so that the
// answer is never identity, and the expected transform with it folded in.

#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include "boicp/util/types.hpp"
#include "dataset_table.hpp"
#include "evaluation.hpp"

namespace boicp::bench {

struct BenchPair {
  std::string dataset;
  std::string source_name;  // as written in pairs.csv
  std::string target_name;
  Points source;  // perturbed: P * p for every loaded source point
  Points target;
  Transform perturbation = Transform::Identity();  // P
  Transform expected = Transform::Identity();      // T_ref * P^-1: maps `source` onto `target`
  Point error_point = Point::Zero();  // where the translation error is measured (FieldPair)
  uint64_t method_seed = 0;           // the seed every method uses on this pair
};

/// A perturbation P = Trans(t) * Rot: Rot drawn as settings.perturb says (yaw
/// uniform in [-pi, pi], or a uniform random axis with an angle uniform in
/// [0, max_angle_deg]), t uniform in +-settings.translation_bounds per axis.
Transform DrawPerturbation(const DatasetSettings& settings, std::mt19937_64& rng);

/// The reference pairs of one dataset and the seeds that make pair `index`
/// reproducible on its own.
struct DatasetPairs {
  DatasetSettings settings;
  std::string folder;
  std::vector<ReferencePair> references;  // ReadPairsCsv, full paths
};

/// Reads the CSV (InputError when unreadable or malformed). The dataset name
/// is the CSV's folder name.
DatasetPairs ReadDataset(const std::string& pairs_csv, const DatasetOverrides& overrides);

/// Loads and perturbs pair `index`. Pair seeds come from MixSeed(seed,
/// dataset name, index), so they do not depend on the other selected pairs.
BenchPair LoadPair(const DatasetPairs& dataset, size_t index, uint64_t seed);

/// Builds the BenchPair of reference `index` from its loaded clouds: draws P
/// from the pair's seed, moves the source and folds P into the expected transform.
BenchPair PerturbPair(const DatasetPairs& dataset, size_t index, uint64_t seed, Points source,
                      Points target);

/// `count` pairs of scans of a generated street (no files), for machines
/// without the shared data. Never used for accuracy claims.
DatasetPairs SyntheticDataset(int count, const DatasetOverrides& overrides);
BenchPair MakeSyntheticPair(const DatasetPairs& dataset, size_t index, uint64_t seed);

}  // namespace boicp::bench
