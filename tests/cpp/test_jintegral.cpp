// J at the outer boundary against the compliance and energy release rates of an elastic cracked specimen
// (docs/verification.md): static elastic solutions at three crack lengths, theta_D = 0 and 30.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "measurements.hpp"
#include "simulation.hpp"

using namespace enamel;

namespace {

CaseParams elasticCase(double theta, double a0OverWs) {
  return parseCase("theta_D = " + std::to_string(theta) +
                       "\nEr_over_kd = 10\nsigma_ru_over_sigma0 = 21.4\n"
                       "rods_breakable = false\ninterfaces_breakable = false\n"
                       "w_s_over_d = 30\nh_s_over_d = 16\nh_e_over_d = 0.3\n"
                       "a0_over_ws = " + std::to_string(a0OverWs) + "\n",
                   "elastic", "", {});
}

struct Static { double P, J, energy, a; };

Static solveAt(double theta, double a0) {
  Simulation sim(elasticCase(theta, a0 / 30.0));
  const double U = 0.01;
  sim.solveStaticElastic(U);
  double P = 0;
  for (std::size_t i = 0; i < sim.ops.prescribedDofs.size(); ++i) P += sim.state.reaction[i] * sim.ops.prescribedShape[i];
  // crack length of the discrete model: midway between the last cut slice and the first intact one
  const int lastCut = static_cast<int>(std::ceil(a0 / sim.model.h_e)) - 1;
  return {P, sim.computeJ(), sim.strainEnergyOfBeams() + sim.strainEnergyOfInterfaces(),
          (lastCut + 0.5) * sim.model.h_e};
}

}  // namespace

// G = (P^2 / 2B) dC/da with C = U / P (compliance), and G = -(1/B) dPi/da at fixed U (energy), by central
// differences over +/- 1.5 d; J at the middle crack length. Tolerance 3%: the central difference is
// second order, and the discrete crack front is one slice wide.
TEST(JIntegral, BoundaryJMatchesComplianceAndEnergyReleaseRates) {
  for (double theta : {0.0, 30.0}) {
    const Static lo = solveAt(theta, 13.55), mid = solveAt(theta, 15.05), hi = solveAt(theta, 16.55);
    const double B = std::sqrt(3.0), U = 0.01;
    const double da = hi.a - lo.a;
    ASSERT_NEAR(da, 3.0, 1e-9);
    const double dCda = (U / hi.P - U / lo.P) / da;
    const double Gcompliance = mid.P * mid.P / (2 * B) * dCda;
    const double Genergy = -(hi.energy - lo.energy) / da / B;
    EXPECT_NEAR(mid.energy, 0.5 * mid.P * U, 1e-9 * mid.energy) << "Clapeyron: stored energy = P U / 2";
    EXPECT_GT(mid.J, 0);
    EXPECT_NEAR(mid.J / Gcompliance, 1.0, 0.03) << "theta " << theta << " J " << mid.J << " G_c " << Gcompliance;
    EXPECT_NEAR(mid.J / Genergy, 1.0, 0.03) << "theta " << theta << " J " << mid.J << " G_e " << Genergy;
  }
}

// The loaded faces' terms of J by hand on a small elastic model: the top row's grips have du_y/dx = -U/w_s,
// the bottom row's +U/w_s, taken from the model's own row lists (not from the shape's sign). The nodes at
// x = w_s, where the shape is +/-0, carry a reaction, so a sign test on the shape would give the bottom ones
// the top face's slope: the old sign-test sum is computed too and must differ from the hand value.
TEST(JIntegral, LoadedFacesTermsMatchAHandComputationWithReactionsAtTheRightEdge) {
  Simulation sim(parseCase("theta_D = 30\nEr_over_kd = 10\nsigma_ru_over_sigma0 = 21.4\n"
                           "rods_breakable = false\ninterfaces_breakable = false\n"
                           "w_s_over_d = 6\nh_s_over_d = 4\nh_e_over_d = 0.3\n",
                           "small", "", {}));
  const Model& m = sim.model;
  const double U = 0.02;
  sim.solveStaticElastic(U);
  auto reactionAt = [&](int node) {
    for (std::size_t i = 0; i < sim.ops.prescribedDofs.size(); ++i)
      if (sim.ops.prescribedDofs[i] == 6 * node + 1) return sim.state.reaction[i];
    ADD_FAILURE() << "node " << node << " is not prescribed";
    return 0.0;
  };
  double top = 0, bottom = 0, rightTop = 0, rightBottom = 0, scale = 0;
  for (int node : m.topNodes) {
    top += reactionAt(node) * (-U / m.w_s);
    if (m.nodeSlice[node] == m.numSlices - 1) rightTop += std::abs(reactionAt(node));
    scale = std::max(scale, std::abs(reactionAt(node)));
  }
  for (int node : m.bottomNodes) {
    bottom += reactionAt(node) * (U / m.w_s);
    if (m.nodeSlice[node] == m.numSlices - 1) rightBottom += std::abs(reactionAt(node));
  }
  ASSERT_GT(rightTop, 1e-3 * scale) << "the top row's right-edge grips carry a reaction";
  ASSERT_GT(rightBottom, 1e-3 * scale) << "the bottom row's right-edge grips carry a reaction";

  const double sum = sumGripForceTimesSlope(m, sim.ops, sim.state);
  EXPECT_NEAR(sum, top + bottom, 1e-12 * std::abs(top) + 1e-300);
  const double Wleft = faceEnergyDensity(m, sim.materials, sim.state, 0, 0);
  const double Wright = faceEnergyDensity(m, sim.materials, sim.state, m.numSlices - 1, 1);
  EXPECT_NEAR(sim.computeJ(), (-(top + bottom) + Wright - Wleft) / m.B, 1e-12 * std::abs(top) / m.B);

  double signTest = 0;  // the sign test the slope replaced
  for (std::size_t i = 0; i < sim.ops.prescribedDofs.size(); ++i)
    signTest += sim.state.reaction[i] * (sim.ops.prescribedShape[i] >= 0 ? -U / m.w_s : U / m.w_s);
  EXPECT_GT(std::abs(signTest - (top + bottom)), 1e-3 * std::abs(top))
      << "the shape's sign misreads the right-edge bottom grips, so it must differ from the hand value";
}
