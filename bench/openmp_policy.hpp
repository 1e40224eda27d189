#pragma once
// Start-up policy for the OpenMP that Open3D's baselines (FPFH, RANSAC, FGR)
// run on. The engine itself uses no OpenMP.

namespace boicp {

/// libgomp reads OMP_WAIT_POLICY once, when it is loaded, before main. Its
/// default spins at barriers, and on a shared machine a spinning thread starves
/// the team member it waits for, so a baseline would be timed slower than it
/// is. Unless the user chose a policy, this sets PASSIVE and re-executes the
/// program once (argv unchanged) so that it takes effect. Returns only when no
/// restart is needed or possible (no /proc).
void RestartWithPassiveOpenMpWait(char** argv);

}  // namespace boicp
