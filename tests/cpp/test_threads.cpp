// The case key `threads` sets the thread count of both parallel runtimes the solver uses: OpenMP's (the step's
// kernels) and the BLAS's (CHOLMOD's factorizations and solves), so a one-thread run beside others uses one core.
#include <dlfcn.h>
#include <gtest/gtest.h>
#include <omp.h>

#include <string>

#include "case/case_params.hpp"
#include "simulation/setup.hpp"

using namespace enamel;

namespace {

int blasThreads() {
  using GetThreads = int (*)();
  auto get = reinterpret_cast<GetThreads>(dlsym(RTLD_DEFAULT, "openblas_get_num_threads"));
  return get ? get() : -1;
}

CaseParams withThreads(const char* n) {
  return parseCase("theta_D = 30\nEr_over_kd = 10\nsigma_ru_over_sigma0 = 21.4\n", "case.toml", "ci",
                   {std::string("threads=") + n});
}

}  // namespace

TEST(ThreadCount, OneThreadHoldsForOpenMPAndTheBlas) {
  if (blasThreads() < 0) GTEST_SKIP() << "the BLAS linked here is not OpenBLAS: it has no threads of its own";
  setThreadCount(withThreads("2"), 1000);
  EXPECT_EQ(omp_get_max_threads(), 2);
  EXPECT_GE(blasThreads(), 1);  // OpenBLAS caps it at the cores it was started with: 2 here (2-core AMD EPYC)
  setThreadCount(withThreads("1"), 1000);
  EXPECT_EQ(omp_get_max_threads(), 1);
  EXPECT_EQ(blasThreads(), 1);
}
