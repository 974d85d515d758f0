// The kernels on a small model (kernels.hpp): the per-node gather of interface forces is the sum of the
// tested pointwise function cohesive::computeInterfaceForces, and errors map to their exit statuses (a failed
// factorisation is a failed run, 11; a refused time step is bad input, 7).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <string>

#include "exit_codes.hpp"
#include "kernels.hpp"
#include "runner.hpp"
#include "simulation.hpp"

using namespace enamel;

namespace {

CaseParams smallCase(const std::string& extra) {
  // E_transverse given (not measured) to keep the set-up short.
  return parseCase("theta_D = 30\nEr_over_kd = 10\nsigma_ru_over_sigma0 = 21.4\nE_transverse_over_Er = 0.1\n"
                   "w_s_over_d = 8\nh_s_over_d = 4\n" + extra,
                   "kernels", "", {});
}

// A deterministic field of amplitude `amp` on every DOF.
VecX pseudoRandomField(int n, double amp) {
  VecX q(n);
  std::uint64_t seed = 7;
  for (int i = 0; i < n; ++i) {
    seed = seed * 6364136223846793005ULL + 1442695040888963407ULL;
    q[i] = amp * (static_cast<double>(seed >> 11) / 9007199254740992.0 - 0.5);
  }
  return q;
}

}  // namespace

// f_iface from the gather against the nodal wrenches of computeInterfaceForces summed interface by
// interface. The sums run in different orders, so they agree to round-off: 1e-12 of the largest force.
// The amplitude (3 x delta0) takes interfaces past the elastic range, so the history matters.
TEST(Kernels, InterfaceGatherSumsComputeInterfaceForces) {
  Simulation sim(smallCase("integrator = \"lumped\"\n"));
  const Model& m = sim.model;
  const cohesive::Law& law = sim.materials.law;
  const VecX q = pseudoRandomField(m.numDofs(), 3 * law.delta0());
  std::vector<double> lambdaMax(m.numInterfaces(), 0.0);
  VecX f(m.numDofs());
  const int failed = computeForcesForInterfaces(m, law, sim.ops, q, lambdaMax, true, f);

  VecX expected = VecX::Zero(m.numDofs());
  std::vector<double> lambdaExpected(m.numInterfaces(), 0.0);
  int failedExpected = 0, inelastic = 0;
  for (int i = 0; i < m.numInterfaces(); ++i) {
    const int A = m.ifaceNodes[i][0], B = m.ifaceNodes[i][1];
    const cohesive::NodalWrench w = cohesive::computeInterfaceForces(
        law, m.ifaceGeom[i], q.segment<3>(6 * A), q.segment<3>(6 * A + 3), q.segment<3>(6 * B),
        q.segment<3>(6 * B + 3), lambdaExpected[i]);
    expected.segment<3>(6 * A) -= w.forceA;
    expected.segment<3>(6 * A + 3) -= w.momentA;
    expected.segment<3>(6 * B) -= w.forceB;
    expected.segment<3>(6 * B + 3) -= w.momentB;
    failedExpected += cohesive::isFailed(law, lambdaExpected[i]);
    inelastic += cohesive::isInelastic(law, lambdaExpected[i]);
  }
  ASSERT_GT(inelastic, 0) << "the field should take some interfaces past delta0";
  EXPECT_LE((f - expected).cwiseAbs().maxCoeff(), 1e-12 * expected.cwiseAbs().maxCoeff());
  EXPECT_EQ(failed, failedExpected);
  for (int i = 0; i < m.numInterfaces(); ++i) ASSERT_EQ(lambdaMax[i], lambdaExpected[i]) << "interface " << i;

  // a trial evaluation (update = false) leaves the history as it was
  const std::vector<double> before = lambdaMax;
  computeForcesForInterfaces(m, law, sim.ops, 2.0 * q, lambdaMax, false, f);
  EXPECT_EQ(lambdaMax, before);
}

// A factorisation that fails (H = M + dt/2 C made negative definite) throws SolverError, whose exit status
// is run_failed (11), not out_of_range (7).
TEST(Kernels, FailedFactorisationIsARunFailure) {
  Simulation sim(smallCase("integrator = \"paper\"\n"));
  sim.ops.M = -sim.ops.M;
  sim.ops.K = -sim.ops.K;
  try {
    sim.integrator->updateOperators(sim.ops);
    FAIL() << "factorising a negative definite H should fail";
  } catch (const SolverError& e) {
    EXPECT_EQ(exitCodeOf(e), exit_code::run_failed) << e.what();
  }
}

// A time step above the stable limit is bad input: IntegratorError, exit status out_of_range (7).
TEST(Kernels, RefusedTimeStepIsOutOfRange) {
  try {
    Simulation sim(smallCase("integrator = \"paper\"\ndt_factor = 0.5\n"));
    FAIL() << "dt_factor 0.5 should be refused";
  } catch (const IntegratorError& e) {
    EXPECT_EQ(exitCodeOf(e), exit_code::out_of_range) << e.what();
  }
}
