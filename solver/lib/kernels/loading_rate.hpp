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
// Two rules set phi (case key rate_adapt_rule): `energy` (the default) reacts to what happened in the last
// interval (nextRateMultiplier); `margin` also looks ahead (nextRateMultiplierByMargin): from each element's
// progress toward its failure event (EventProgress) at this row and the last, the rows left until the first
// event, and phi chosen so that the last rows before it run at phi = 1 (docs/solver.md, Adaptive loading rate).
//
// The clock (State::loadingTime, State::rateMultiplier): dtau/dt = phi; the grips follow
//   u_y = +/- U(tau) (1 - x/w_s),  velocity phi U'(tau),  acceleration phi^2 U''(tau) + phi' U'(tau),
// with U the Loading of the case (ramped v_app). phi changes linearly over a control interval (from its value
// at one control point to the next target), so the grips' velocity stays continuous: over each time step phi is
// linear, phi_{n+1} = phi_n + (phi_target - phi_n) / (steps left in the ramp), reaching the target exactly.
#include <cmath>

#include "data/state.hpp"

namespace enamel {

// The rule's bounds (the quasi-static warning bound, runner.hpp kKineticWarn, is 0.05).
constexpr double kRateRhoHigh = 0.01;     // rho = kinetic / strain above this: halve phi (the default of the
                                          // case key rate_adapt_rho_high)
constexpr double kRateRhoLowShare = 0.25; // rho below this share of the high bound (and nothing broke): raise phi
constexpr double kRateRhoLow = kRateRhoLowShare * kRateRhoHigh;  // 0.0025 at the default
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
  double rowsToEvent = NAN; // the margin rule's forecast (EventForecast::rows); NaN: none (the energy rule)
  double rhoHigh = kRateRhoHigh;  // the high bound on rho (case key rate_adapt_rho_high); the low one is
                                  // kRateRhoLowShare x this
};

/// The rule (pure): with rho = kinetic / strain, rho_hi = in.rhoHigh (kRateRhoHigh unless the case sets
/// rate_adapt_rho_high) and rho_lo = kRateRhoLowShare x rho_hi,
///   lower (phi / 2, not below 1)            when a rod element was deleted or rho > rho_hi;
///   raise (phi x 1.25, not above phiMax)    when rho < rho_lo, no rod element was deleted and no more
///                                           than burstInterfaces interfaces failed;
///   hold otherwise (also while there is no strain energy yet and nothing was deleted: rho is undefined).
/// The result is always within [1, max(phi, phiMax)].
double nextRateMultiplier(double phi, double phiMax, const RateControlInput& in);

/// The margin rule's forecast of one element: the loading time until its progress p (failure at p = 1) reaches
/// 1 at the pace of the last interval, (1 - now) dtau / (now - before) when p rose over the loading time dtau;
/// 0 when p is at or past 1; +inf when it did not rise or either value is NaN (an element past its event, or
/// not measured yet).
double timeToEvent(double before, double now, double dtau);

/// The margin rule's forecast at a history row, in history rows at phi = 1 (rows of loading time rowTime =
/// history_every dt): the earliest timeToEvent over the rod elements and over the interfaces, from the
/// progress at the last row (`before`) and now, and the loading the last interval covered (EventForecast,
/// state.hpp). NaN where `before` holds no measurement (the first row, or a kind whose vectors differ in size);
/// +inf where no element's progress rose.
EventForecast forecastEvents(const EventProgress& before, const EventProgress& now, double rowTime);

/// The forecast's own trend (pure): an element that accelerates toward its event (a softening interface
/// does) makes the forecast fall by more than the loading the interval covered; then the rows until the
/// forecast itself reaches 0 at the pace it fell, rowsNow rowsElapsed / (rowsBefore - rowsNow), are fewer than
/// rowsNow and taken instead. rowsNow when it fell by no more than rowsElapsed, rose, or either forecast is
/// not finite (NaN stays NaN).
double trendedRows(double rowsBefore, double rowsNow, double rowsElapsed, double within);

/// The rows the margin rule reads (pure): the earlier of the rod break and the interface failure, each
/// trendedRows from the last row's forecast to this one's; NaN when this one's is NaN.
double rowsToFirstEvent(const EventForecast& last, const EventForecast& now, double within);

/// The margin rule's target (pure): phi = rowsToEvent / horizon, within [1, phiMax], so that the forecast event
/// is `horizon` rows away at the rate chosen and the rate reaches 1 as the event comes within `horizon` rows
/// (phi falls by the factor 1 - 1/horizon per row while the forecast holds); 1 when the forecast is NaN.
double marginRateTarget(double rowsToEvent, double horizon, double phiMax);

/// The margin rule (pure): the smaller of the energy rule's phi (nextRateMultiplier: its halving, its hold on
/// a burst and its rise of x1.25 a row at most) and marginRateTarget(in.rowsToEvent, horizon, phiMax). Within
/// [1, max(phi, phiMax)].
double nextRateMultiplierByMargin(double phi, double phiMax, double horizon, const RateControlInput& in);

/// The velocity correction at a change of phi (case key rate_adapt_velocity = quasi_static; pure): loaded
/// proportionally, a linear specimen moves quasi-statically at v = phi (U'(tau)/U(tau)) q (the motion that
/// Measurement::kineticBeyond takes out); when phi goes from phiBefore to phiAfter over a step, that motion
/// changes by (phiAfter - phiBefore) (U'/U) q. Returns the factor c of q, c = (phiAfter - phiBefore) U' / U:
/// 0 when phi did not change or U <= 0 (no proportional motion to follow). U' = dU/dtau (Loading::velocity).
double quasiStaticVelocityFactor(double phiBefore, double phiAfter, double velocity, double displacement);

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
