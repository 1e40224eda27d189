#include "thread_budget.hpp"

#include <omp.h>

#include <cstdlib>
#include <string>

namespace boicp::bench {

void ApplyThreadBudget(int threads) {
  ::setenv("OMP_NUM_THREADS", std::to_string(threads).c_str(), /*overwrite=*/1);
  omp_set_num_threads(threads);
}

}  // namespace boicp::bench
