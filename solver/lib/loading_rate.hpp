#pragma once
// The adaptive loading rate (case key rate_adapt_max; README Performance): a loading clock tau that runs phi
// times as fast as the time t, and the rule that sets phi from the measured kinetic / strain energy and what
// broke. Off (rate_adapt_max = 1): tau = t and every result is today's, bit for bit.
//
// The kinetic energy it uses is the part beyond the quasi-static motion: 1/2 w^T M w with w = v - (U'/U) q
// (Measurement::kineticBeyond). The whole kinetic energy includes the loading's own motion, (U'/U)^2 q^T M q,
// which in a large specimen is not small: at the `paper` preset after the static start it is 1.8% of the
// strain energy (the specimen's slowest modes carry the grips' motion), above rho_hi at phi = 1, so a rule on
// the whole kinetic energy never raised the rate there.
//
// The clock (State::loadingTime, State::rateMultiplier): dtau/dt = phi; the grips follow
//   u_y = +/- U(tau) (1 - x/w_s),  velocity phi U'(tau),  acceleration phi^2 U''(tau) + phi' U'(tau),
// with U the Loading of the case (ramped v_app). phi changes linearly over a control interval (from its value
// at one control point to the next target), so the grips' velocity stays continuous: over each time step phi is
// linear, phi_{n+1} = phi_n + (phi_target - phi_n) / (steps left in the ramp), reaching the target exactly.
#include "state.hpp"

namespace enamel {

// The rule's bounds (the quasi-static warning bound, runner.hpp kKineticWarn, is 0.05).
constexpr double kRateRhoHigh = 0.01;     // rho = kinetic / strain above this: halve phi
constexpr double kRateRhoLow = 0.0025;    // rho below this (and nothing broke): raise phi
constexpr double kRateRaise = 1.25;       // raise: phi x 1.25 (not above rate_adapt_max)
constexpr double kRateLower = 0.5;        // lower: phi x 0.5 (not below 1)
constexpr int kRateBurstSlices = 4;       // a burst: more interfaces failed in the interval than this many
                                          // slices' worth of the crack plane's interfaces

/// What the rate controller sees of one control interval (the history interval).
struct RateControlInput {
  double kinetic = 0;       // kinetic energy beyond the loading's motion at the end of the interval
  double strain = 0;        // strain energy of rod elements + interfaces at the end of the interval
  int rodsDeleted = 0;      // rod elements deleted during the interval
  int interfacesFailed = 0; // interfaces that failed during the interval
  int burstInterfaces = 0;  // more failures than this in one interval are a burst
};

/// The rule (pure): with rho = kinetic / strain,
///   lower (phi / 2, not below 1)            when a rod element was deleted or rho > kRateRhoHigh;
///   raise (phi x 1.25, not above phiMax)    when rho < kRateRhoLow, no rod element was deleted and no more
///                                           than burstInterfaces interfaces failed;
///   hold otherwise (also while there is no strain energy yet and nothing was deleted: rho is undefined).
/// The result is always within [1, max(phi, phiMax)].
double nextRateMultiplier(double phi, double phiMax, const RateControlInput& in);

/// Interfaces of one slice on the crack plane (the pre-cracked interfaces per pre-cracked slice, at least 1)
/// x kRateBurstSlices: the burst threshold of a model.
int burstInterfacesOf(const Model& m);

/// Start a linear ramp of phi from its value now to `target` over `steps` time steps.
void setRateMultiplierTarget(State& s, double target, long steps);

/// phi at the end of the step ahead (phi_{n+1}: the ramp's next value, or phi_n when no ramp is running).
double rateMultiplierAfterStep(const State& s);

/// The loading clock at t_n + h (h in [-dt, dt]; phi linear over the step ahead, extrapolated before t_n):
/// tau, phi, and phi' = dphi/dt.
struct LoadingClock {
  double tau = 0, phi = 1, phiRate = 0;
};
LoadingClock loadingClockAt(const State& s, double h, double dt);

/// After t_{n+1} = t_n + dt: tau_{n+1} = tau_n + dt (phi_n + phi_{n+1}) / 2 (exact for phi linear over the
/// step), phi_{n+1}, and the ramp one step shorter. Off (Loading::adaptive() false): tau_{n+1} = t_{n+1}.
void advanceLoadingClock(const Loading& loading, double dt, State& s);

}  // namespace enamel
