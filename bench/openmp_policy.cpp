#include "openmp_policy.hpp"

#include <limits.h>
#include <unistd.h>

#include <cstdlib>

namespace boicp {

void RestartWithPassiveOpenMpWait(char** argv) {
  if (std::getenv("OMP_WAIT_POLICY") != nullptr) return;
  ::setenv("OMP_WAIT_POLICY", "PASSIVE", /*overwrite=*/0);
  // The resolved path keeps the process name (not "exe").
  char self[PATH_MAX];
  const ssize_t length = ::readlink("/proc/self/exe", self, sizeof(self) - 1);
  if (length <= 0) return;  // no /proc: run on with OpenMP's default policy
  self[length] = '\0';
  ::execv(self, argv);
}

}  // namespace boicp
