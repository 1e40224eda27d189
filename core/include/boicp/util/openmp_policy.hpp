#pragma once
// Process start-up policy for OpenMP, shared by every long-running binary.

namespace boicp {

/// libgomp reads OMP_WAIT_POLICY once, when it is loaded, before main. Its
/// default spins at barriers, and on a shared machine a spinning thread starves
/// the team member it waits for: short parallel ICP loops ran 5-10x slower with
/// 2 threads than with 1. Unless the user chose a policy, this sets PASSIVE and
/// re-executes the program once (argv unchanged) so that it takes effect.
/// Returns only when no restart is needed or possible (no /proc).
void RestartWithPassiveOpenMpWait(char** argv);

}  // namespace boicp
