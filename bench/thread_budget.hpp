#pragma once
// One thread budget for every method in the run.

namespace boicp::bench {

/// Caps OpenMP, and with it Open3D, at `threads`. Call from the main thread
/// before any Open3D call: Open3D's FPFH and RANSAC size their teams with
/// utility::EstimateMaxThreads(), which ignores omp_set_num_threads and
/// returns every core unless OMP_NUM_THREADS is set, so both are set here.
void ApplyThreadBudget(int threads);

}  // namespace boicp::bench
