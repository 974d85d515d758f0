// J at the outer boundary against the compliance and energy release rates of an elastic cracked specimen
// (docs/verification.md): static elastic solutions at three crack lengths, theta_D = 0 and 30.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>

#include "kernels/measurements.hpp"
#include "simulation/simulation.hpp"

using namespace enamel;

namespace {

// `grips`: more case lines (the grips' keys), none by default.
CaseParams elasticCase(double theta, double a0OverWs, const std::string& grips = "") {
  return parseCase("theta_D = " + std::to_string(theta) +
                       "\nEr_over_kd = 10\nsigma_ru_over_sigma0 = 21.4\n"
                       "rods_breakable = false\ninterfaces_breakable = false\n"
                       "w_s_over_d = 30\nh_s_over_d = 16\nh_e_over_d = 0.3\n"
                       "a0_over_ws = " + std::to_string(a0OverWs) + "\n" + grips,
                   "elastic", "", {});
}

// terms: |sum F_y du_y/dx| + W_right + W_left over B, the boundary terms J is the sum of (J's conditioning)
struct Static { double P, J, energy, a, terms = 0; };

Static solveAt(double theta, double a0, const std::string& grips = "") {
  Simulation sim(elasticCase(theta, a0 / 30.0, grips));
  const double U = 0.01;
  sim.solveStaticElastic(U);
  double P = 0;
  for (std::size_t i = 0; i < sim.ops.prescribedDofs.size(); ++i) P += sim.state.reaction[i] * sim.ops.prescribedShape[i];
  // crack length of the discrete model: midway between the last cut slice and the first intact one
  const int lastCut = static_cast<int>(std::ceil(a0 / sim.model.h_e)) - 1;
  const Model& m = sim.model;
  const double terms = (std::abs(sumGripForceTimesSlope(m, sim.ops, sim.state)) +
                        faceEnergyDensity(m, sim.materials, sim.state, 0, 0) +
                        faceEnergyDensity(m, sim.materials, sim.state, m.numSlices - 1, 1)) / m.B;
  return {P, sim.computeJ(), sim.strainEnergyOfBeams() + sim.strainEnergyOfInterfaces(),
          (lastCut + 0.5) * sim.model.h_e, terms};
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

// Every grip profile and constraint (case keys grip_profile, grip_constraint): J at the outer boundary, with the
// loaded faces' slope of each profile, against the compliance and energy release rates of the same grips, as in
// BoundaryJMatchesComplianceAndEnergyReleaseRates (P the force conjugate to U: sum of reaction x shape), at
// theta_D = 30. J is the sum of the loaded faces' term and the face energies. With the grips turning to the right
// edge those terms are about G itself, and J agrees with G within 4% (measured: 2.3% for uy, 3.4% for uxuy).
// Turning about the centre, the pre-crack tip at a0 = w_s/2 sits where u_y = 0 and the right part of the
// specimen is compressed: J is then the difference of a loaded faces' term and a right-face energy each 20-30 G,
// and their discretisation error, a few percent of them (1.8% for uy, 6.4% for uxuy), is most of G (J/G = 0.26
// and -0.83): the outer-boundary J does not measure G there, and the test states that conditioning and bounds
// the error by 10% of the terms rather than claiming agreement (docs/model.md, Loading). The grips do change the
// specimen's compliance (each case tests its own shape and slope, not the default's). These bounds hold with the
// tip's crisscross intact (crisscross_at_tip = "intact"), which the loop pins; with the default cut tip the
// crisscross lattice near the tip differs (it moves with a0 in both readings) and J/G_c is 0.955 for
// to_right_edge uxuy (4.5%): the default's grips (to_right_edge, uy) are checked at the cut tip, within 3%, by
// BoundaryJMatchesComplianceAndEnergyReleaseRates.
TEST(JIntegral, BoundaryJAgainstComplianceForEveryGripProfileAndConstraint) {
  const double theta = 30.0, B = std::sqrt(3.0), U = 0.01;
  const std::string intact = "crisscross_at_tip = \"intact\"\n";
  const double defaultP = solveAt(theta, 15.05, intact).P;
  for (const char* profile : {"to_right_edge", "about_centre"})
    for (const char* constraint : {"uy", "uxuy"}) {
      const std::string grips = intact + "grip_profile = \"" + profile + "\"\ngrip_constraint = \"" + constraint + "\"\n";
      const Static lo = solveAt(theta, 13.55, grips), mid = solveAt(theta, 15.05, grips), hi = solveAt(theta, 16.55, grips);
      const double da = hi.a - lo.a;
      const double Gcompliance = mid.P * mid.P / (2 * B) * (U / hi.P - U / lo.P) / da;
      const double Genergy = -(hi.energy - lo.energy) / da / B;
      const std::string what = std::string(profile) + " " + constraint + ": J/G_c " +
                               std::to_string(mid.J / Gcompliance) + " terms/G_c " +
                               std::to_string(mid.terms / Gcompliance);
      EXPECT_NEAR(mid.energy, 0.5 * mid.P * U, 1e-9 * mid.energy) << what << ": Clapeyron";
      EXPECT_NEAR(Genergy / Gcompliance, 1.0, 0.03) << what;
      if (std::string(profile) == "to_right_edge") {
        EXPECT_LT(mid.terms, 1.2 * Gcompliance) << what << ": J is well conditioned";
        EXPECT_GT(mid.J, 0) << what;
        EXPECT_NEAR(mid.J / Gcompliance, 1.0, 0.04) << what;
        EXPECT_NEAR(mid.J / Genergy, 1.0, 0.04) << what;
      } else {
        EXPECT_GT(mid.terms, 10.0 * Gcompliance) << what << ": J is the difference of terms much larger than G";
        EXPECT_NEAR(mid.J, Gcompliance, 0.1 * mid.terms) << what;
        EXPECT_NEAR(mid.J, Genergy, 0.1 * mid.terms) << what;
      }
      if (std::string(profile) != "to_right_edge" || std::string(constraint) != "uy")
        EXPECT_GT(std::abs(mid.P / defaultP - 1.0), 0.01) << what << ": the grips change the compliance";
    }
}

// The loaded faces' terms by hand for the rotation about the centre with u_x held: du_y/dx = -2U/w_s on the top
// row, +2U/w_s on the bottom row (taken from the row lists), and the u_x grips add nothing (du_x/dx = 0 along
// the faces) though they carry a reaction; their shape is 0, so they do no work and add nothing to P.
TEST(JIntegral, LoadedFacesTermsAboutTheCentreWithUxHeld) {
  Simulation sim(parseCase("theta_D = 30\nEr_over_kd = 10\nsigma_ru_over_sigma0 = 21.4\n"
                           "rods_breakable = false\ninterfaces_breakable = false\n"
                           "w_s_over_d = 6\nh_s_over_d = 4\nh_e_over_d = 0.3\n"
                           "grip_profile = \"about_centre\"\ngrip_constraint = \"uxuy\"\n",
                           "small", "", {}));
  const Model& m = sim.model;
  const Operators& ops = sim.ops;
  const double U = 0.02;
  sim.solveStaticElastic(U);
  ASSERT_EQ(ops.prescribedDofs.size(), 2 * (m.topNodes.size() + m.bottomNodes.size()));
  auto indexOf = [&](int dof) {
    for (std::size_t i = 0; i < ops.prescribedDofs.size(); ++i)
      if (ops.prescribedDofs[i] == dof) return i;
    ADD_FAILURE() << "DOF " << dof << " is not prescribed";
    return std::size_t(0);
  };
  double hand = 0, xReactions = 0;
  for (const auto& [nodes, sign] : {std::make_pair(&m.topNodes, 1.0), std::make_pair(&m.bottomNodes, -1.0)})
    for (int node : *nodes) {
      const std::size_t iy = indexOf(6 * node + 1), ix = indexOf(6 * node);
      EXPECT_EQ(ops.prescribedShape[iy], sign * (1.0 - 2.0 * (m.X[node].x() / m.w_s)));
      EXPECT_EQ(sim.state.q[6 * node + 1], ops.prescribedShape[iy] * U);
      EXPECT_EQ(sim.state.q[6 * node], 0.0);
      EXPECT_EQ(ops.prescribedShape[ix], 0.0);
      hand += sim.state.reaction[iy] * (-sign * 2.0 * U / m.w_s);
      xReactions += std::abs(sim.state.reaction[ix]);
    }
  EXPECT_GT(xReactions, 1e-6 * std::abs(hand) * m.w_s / U) << "the u_x grips carry a reaction";
  EXPECT_NEAR(sumGripForceTimesSlope(m, ops, sim.state), hand, 1e-12 * std::abs(hand));
  const double Wleft = faceEnergyDensity(m, sim.materials, sim.state, 0, 0);
  const double Wright = faceEnergyDensity(m, sim.materials, sim.state, m.numSlices - 1, 1);
  EXPECT_NEAR(sim.computeJ(), (-hand + Wright - Wleft) / m.B, 1e-12 * std::abs(hand) / m.B);
  double P = 0;
  for (int node : m.topNodes) P += sim.state.reaction[indexOf(6 * node + 1)] * (1.0 - 2.0 * m.X[node].x() / m.w_s);
  for (int node : m.bottomNodes) P -= sim.state.reaction[indexOf(6 * node + 1)] * (1.0 - 2.0 * m.X[node].x() / m.w_s);
  EXPECT_NEAR(computeGripLoad(ops, sim.state), P, 1e-12 * std::abs(P));
}

