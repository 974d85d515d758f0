// Dynamics of the time integrators against theory: the axial wave speed of the
// rods, the energy balance of an undamped elastic run, and the damping ratio of a single mode.
//
// At theta_D = 0 the rods run along x. A field u_x(x) that is the same in every rod opens no interface
// (rigid-arm kinematics: equal displacements, no rotations), so the specimen is a bundle of free-free bars:
// a pulse travels at c_r = sqrt(E_r / rho_r) = 1 and the first free-free mode is u_x = cos(pi x / L).
#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <string>
#include <vector>

#include "integrators/integrators.hpp"
#include "simulation/simulation.hpp"

using namespace enamel;

namespace {

CaseParams bundleCase(const std::string& extra) {
  // E_transverse given (not measured) to keep the set-up short; it only sets c_d, the rate and the damping.
  return parseCase("theta_D = 0\nEr_over_kd = 10\nsigma_ru_over_sigma0 = 21.4\n"
                   "rods_breakable = false\ninterfaces_breakable = false\nE_transverse_over_Er = 0.1\n" + extra,
                   "dynamics", "", {});
}

// Give every rod the same axial field u_x = u(x), v_x = v(x), nothing else; grips held at rest.
template <class U, class V>
void setAxialField(Simulation& sim, U u, V v) {
  sim.materials.loading.vApp = 0;
  sim.state.q.setZero();
  sim.state.v.setZero();
  sim.state.a.setZero();
  for (int node = 0; node < sim.model.numNodes(); ++node) {
    const double x = sim.model.X[node].x();
    sim.state.q[6 * node] = u(x);
    sim.state.v[6 * node] = v(x);
  }
  sim.integrator->initialise(sim.model, sim.materials, sim.ops, sim.state);
}

// Centroid along x of u_x^2 (the pulse position).
double pulseCentroid(const Simulation& sim) {
  double sw = 0, sx = 0;
  for (int node = 0; node < sim.model.numNodes(); ++node) {
    const double w = sim.state.q[6 * node] * sim.state.q[6 * node];
    sw += w;
    sx += w * sim.model.X[node].x();
  }
  return sx / sw;
}

void advanceTo(Simulation& sim, double t) {
  while (sim.state.time < t - 0.5 * sim.integrator->timeStep()) sim.step();
}

}  // namespace

// A Gaussian pulse u = A exp(-(x - x0)^2 / 2 s^2) launched to the right (v = -c u'). Its centroid must move
// at c_r = 1 within 1% (the acceptance bound). The discrete dispersion of a linear element is about (k h_e)^2 / 24 ~ 1e-3
// for s = 2 d, h_e = 0.3 d; the pulse stays 8 s away from the ends over the run.
TEST(Dynamics, AxialWaveFrontTravelsAtRodWaveSpeed) {
  for (const char* integrator : {"paper", "lumped"}) {
    Simulation sim(bundleCase("w_s_over_d = 40\nh_s_over_d = 4\nzeta = 0\nintegrator = \"" +
                              std::string(integrator) + "\"\n"));
    const double A = 1e-3, x0 = 10, s = 2;
    auto u = [&](double x) { return A * std::exp(-0.5 * (x - x0) * (x - x0) / (s * s)); };
    auto dudx = [&](double x) { return -(x - x0) / (s * s) * u(x); };
    setAxialField(sim, u, [&](double x) { return -1.0 * dudx(x); });
    const double c0 = pulseCentroid(sim), T = 14;
    advanceTo(sim, T);
    const double speed = (pulseCentroid(sim) - c0) / sim.state.time;
    std::cout << "[ measured ] " << integrator << ": pulse speed " << speed << "\n";
    EXPECT_NEAR(speed, 1.0, 0.01) << integrator << ": pulse speed " << speed << " vs c_r = 1";
  }
}

// Undamped elastic specimen with interfaces (theta_D = 30, rods and interfaces unbreakable, zeta = 0) loaded by
// the graded grip velocity: the external work must equal kinetic + strain energy of rods and interfaces. The
// paper scheme's energy error (the trapezoid rule on the grip power, Newmark's O(dt^2) energy oscillation)
// must stay below 1e-4 of the energy injected at every check (the acceptance bound). The lumped scheme's balance lags by
// one step (its kinetic energy uses v_{n+1/2} and its grip work is booked up to t_n, while q is at t_{n+1}):
// the error is about dt P / W_ext, 5% in the first steps of the ramp where W_ext ~ t^5, 2.4e-3 at the end
// of the ramp and 1.5e-3 at 3 T_r (measured); it is held to 4e-3 from the end of the ramp on (measured 2.8e-3).
TEST(Dynamics, UndampedElasticRunConservesEnergy) {
  for (const auto& [integrator, bound] : {std::pair<const char*, double>{"paper", 1e-4}, {"lumped", 4e-3}}) {
    Simulation sim(parseCase("theta_D = 30\nEr_over_kd = 10\nsigma_ru_over_sigma0 = 21.4\n"
                             "rods_breakable = false\ninterfaces_breakable = false\nE_transverse_over_Er = 0.1\n"
                             "w_s_over_d = 10\nh_s_over_d = 6\nzeta = 0\nv_app_over_cd = 0.01\n"
                             "integrator = \"" + std::string(integrator) + "\"\n",
                             "drift", "", {}));
    const double T = 3 * sim.materials.loading.rampTime;  // ramp up, then two ramp times at constant grip velocity
    double worst = 0, injected = 0;
    for (int check = 1; check <= 30; ++check) {
      advanceTo(sim, T * check / 30.0);
      const double stored = sim.integrator->kineticEnergy(sim.ops, sim.state) + sim.strainEnergyOfBeams() +
                            sim.strainEnergyOfInterfaces();
      injected = sim.state.externalWork;
      const bool judged = std::string(integrator) == "paper" || sim.state.time >= sim.materials.loading.rampTime;
      if (injected > 0 && judged) worst = std::max(worst, std::abs(injected - stored) / injected);
    }
    std::cout << "[ measured ] " << integrator << ": largest energy error " << worst << "\n";
    EXPECT_GT(injected, 0);
    EXPECT_LT(worst, bound) << integrator << ": largest |W_ext - E| / W_ext " << worst;
  }
}

namespace {
double rayleighRatioOfFirstMode(const std::string& scheme) {
  Simulation sim(bundleCase("w_s_over_d = 12\nh_s_over_d = 4\n" + scheme));
  double L = 0;
  for (const auto& x : sim.model.X) L = std::max(L, x.x());
  const double w1 = M_PI / L;
  return 0.5 * (sim.materials.dampA / w1 + sim.materials.dampB * w1);
}
// The measured damping ratio of the first free-free axial mode (below).
double measuredSingleModeDampingRatio(const std::string& scheme) {
  Simulation sim(bundleCase("w_s_over_d = 12\nh_s_over_d = 4\n" + scheme));
  double L = 0;
  for (const auto& x : sim.model.X) L = std::max(L, x.x());
  const double w1 = M_PI / L;
  const double expected = 0.5 * (sim.materials.dampA / w1 + sim.materials.dampB * w1);
  EXPECT_GT(expected, 0.05);
  setAxialField(sim, [&](double x) { return 1e-3 * std::cos(M_PI * x / L); }, [](double) { return 0.0; });
  // modal coordinate: projection of u_x on the mode shape
  auto modal = [&] {
    double num = 0, den = 0;
    for (int node = 0; node < sim.model.numNodes(); ++node) {
      const double phi = std::cos(M_PI * sim.model.X[node].x() / L);
      num += phi * sim.state.q[6 * node];
      den += phi * phi;
    }
    return num / den;
  };
  std::vector<double> extrema;
  double prev2 = modal(), prev1 = prev2;
  const double T = 2.2 * (2 * M_PI / w1);
  while (sim.state.time < T) {
    sim.step();
    const double now = modal();
    if (std::abs(prev1) > std::abs(prev2) && std::abs(prev1) >= std::abs(now) && sim.state.step > 1)
      extrema.push_back(std::abs(prev1));
    prev2 = prev1;
    prev1 = now;
  }
  extrema.insert(extrema.begin(), 1e-3);  // the release is the first extremum
  EXPECT_GE(extrema.size(), 4u);
  const double halfPeriods = static_cast<double>(extrema.size() - 1);
  const double delta = std::log(extrema.front() / extrema.back()) / halfPeriods;  // per half period
  const double measured = delta / std::sqrt(M_PI * M_PI + delta * delta);
  std::cout << "[ measured ] " << scheme << "zeta " << measured << " (Rayleigh " << expected << ", w_1 " << w1
            << ", " << extrema.size() - 1 << " half periods)\n";
  return measured;
}

}  // namespace

// The first free-free axial mode u_x = A cos(pi x / L) released from rest under the run's own Rayleigh damping
// (zeta = 0.2 at w_min = pi c_d / h_s, specimen chosen so that w_1 = pi / L is close to w_min): successive
// extrema of the modal coordinate decay by exp(pi zeta / sqrt(1 - zeta^2)), which must give
// zeta(w_1) = (a / w_1 + b w_1) / 2 within 5% (the acceptance bound).
// `lumped` (rod_damping implicit) takes the same C = a M + b K; capped, its b' = damping_cap / omega_max is far below
// b and the mode is damped at about half the ratio (at this small h_s): the paper's only with the implicit rods.
TEST(Dynamics, SingleModeDampingRatioMatchesRayleigh) {
  for (const char* scheme : {"integrator = \"paper\"\n", "integrator = \"lumped\"\n"}) {
    SCOPED_TRACE(scheme);
    const double measured = measuredSingleModeDampingRatio(scheme);
    EXPECT_NEAR(measured / rayleighRatioOfFirstMode(scheme), 1.0, 0.05) << "measured zeta " << measured;
  }
  const char* capped = "integrator = \"lumped\"\nrod_damping = \"capped\"\n";
  EXPECT_LT(measuredSingleModeDampingRatio(capped), 0.9 * rayleighRatioOfFirstMode(capped));  // measured 0.51 x
}

// On every free row, lumped's step with q_n = 0 (no elastic or interface force) leaves
//   M (v_{n+1/2} - v_{n-1/2}) / dt + a M (v_{n+1/2} + v_{n-1/2}) / 2 = -b K v_{n+1/2}:
// the damping force is the paper's b K of the rods at the new velocity, K the assembled sparse stiffness (not the
// solve's blocks), to round-off. theta_D = 30: rods across slices, grips on both edges.
TEST(Dynamics, LumpedDampingForceIsBKOfTheRods) {
  Simulation sim(parseCase("theta_D = 30\nEr_over_kd = 10\nsigma_ru_over_sigma0 = 21.4\n"
                           "rods_breakable = false\ninterfaces_breakable = false\nE_transverse_over_Er = 0.1\n"
                           "w_s_over_d = 8\nh_s_over_d = 4\nintegrator = \"lumped\"\n",
                           "damping force", "", {}));
  sim.materials.loading.vApp = 0;
  sim.state.q.setZero();
  std::uint64_t seed = 7;
  for (int dof : sim.ops.freeDofs) {
    seed = seed * 6364136223846793005ULL + 1442695040888963407ULL;
    sim.state.vHalf[dof] = static_cast<double>(seed >> 11) / 9007199254740992.0 - 0.5;
  }
  for (int dof : sim.ops.prescribedDofs) sim.state.vHalf[dof] = 0;
  const VecX before = sim.state.vHalf;
  sim.step();
  const VecX& after = sim.state.vHalf;
  const double dt = sim.integrator->timeStep(), a = sim.materials.dampA, b = sim.materials.dampB;
  ASSERT_GT(b * dt, 0.01);
  const VecX bKv = b * (sim.ops.K * after);
  double worst = 0, largest = 0;
  for (int dof : sim.ops.freeDofs) {  // m: the lumped mass, from the scheme's own kinetic energy of a unit DOF
    State unit = sim.state;
    unit.vHalf.setZero();
    unit.vHalf[dof] = 1;
    const double m = 2 * sim.integrator->kineticEnergy(sim.ops, unit);
    const double force = -(m * (after[dof] - before[dof]) / dt + a * m * 0.5 * (after[dof] + before[dof]));
    worst = std::max(worst, std::abs(force - bKv[dof]));
    largest = std::max(largest, std::abs(bKv[dof]));
  }
  std::cout << "[ measured ] largest |damping force - b K v| " << worst << " of largest |b K v| " << largest << "\n";
  EXPECT_GT(largest, 1.0);
  EXPECT_LT(worst, 1e-9 * largest);
}
