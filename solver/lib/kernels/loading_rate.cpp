#include "kernels/loading_rate.hpp"

#include <algorithm>
#include <cmath>
#include <set>
#include <vector>

namespace enamel {

// rho = kinetic / strain; lower on a deletion or rho > rho_hi, raise when rho < rho_lo and quiet, else hold
// (rho_lo = kRateRhoLowShare rho_hi: a power of two, so the default's rho_lo is kRateRhoLow exactly).
double nextRateMultiplier(double phi, double phiMax, const RateControlInput& in) {
  const bool deleted = in.rodsDeleted > 0;
  const bool burst = in.interfacesFailed > in.burstInterfaces;
  if (deleted) return std::max(1.0, kRateLower * phi);
  if (!(in.strain > 0)) return phi;  // no rho yet
  const double rho = in.kinetic / in.strain;
  if (rho > in.rhoHigh) return std::max(1.0, kRateLower * phi);
  if (rho < kRateRhoLowShare * in.rhoHigh && !burst) return std::min(phiMax, kRateRaise * phi);
  return phi;
}

// (1 - now) dtau / (now - before) while rising; 0 at or past 1; NaN comparisons are false: +inf.
double timeToEvent(double before, double now, double dtau) {
  if (now >= 1.0) return 0.0;
  if (!(now > before) || !(dtau > 0)) return INFINITY;
  return (1.0 - now) * dtau / (now - before);
}

namespace {
// The earliest timeToEvent over one kind of element, in rows; NaN when `before` is not a measurement of them.
double earliestRows(const std::vector<double>& before, const std::vector<double>& now, double dtau, double rowTime) {
  if (before.size() != now.size() || std::isnan(dtau)) return NAN;
  double earliest = INFINITY;
  for (std::size_t i = 0; i < now.size(); ++i) earliest = std::min(earliest, timeToEvent(before[i], now[i], dtau));
  return earliest / rowTime;
}
}  // namespace

EventForecast forecastEvents(const EventProgress& before, const EventProgress& now, double rowTime) {
  const double dtau = now.loadingTime - before.loadingTime;
  return EventForecast{earliestRows(before.rods, now.rods, dtau, rowTime),
                       earliestRows(before.interfaces, now.interfaces, dtau, rowTime), dtau / rowTime};
}

// fell by more than the loading covered: rowsNow rowsElapsed / fall (< rowsNow); else rowsNow
double trendedRows(double rowsBefore, double rowsNow, double rowsElapsed, double within) {
  const double fall = rowsBefore - rowsNow;
  if (!(rowsNow < within)) return rowsNow;
  if (!std::isfinite(fall) || !std::isfinite(rowsElapsed) || !(fall > rowsElapsed)) return rowsNow;
  return rowsNow * rowsElapsed / fall;
}

double rowsToFirstEvent(const EventForecast& last, const EventForecast& now, double within) {
  if (std::isnan(now.rowsToRodBreak) || std::isnan(now.rowsToInterfaceFailure)) return NAN;
  return std::min(trendedRows(last.rowsToRodBreak, now.rowsToRodBreak, now.rowsElapsed, within),
                  trendedRows(last.rowsToInterfaceFailure, now.rowsToInterfaceFailure, now.rowsElapsed, within));
}

// rows / horizon within [1, phiMax]; NaN (no forecast): 1
double marginRateTarget(double rowsToEvent, double horizon, double phiMax) {
  if (std::isnan(rowsToEvent)) return 1.0;
  return std::clamp(rowsToEvent / horizon, 1.0, std::max(1.0, phiMax));
}

double nextRateMultiplierByMargin(double phi, double phiMax, double horizon, const RateControlInput& in) {
  return std::max(1.0, std::min(nextRateMultiplier(phi, phiMax, in), marginRateTarget(in.rowsToEvent, horizon, phiMax)));
}

// c = (phi' - phi) U'/U; 0 without a change or a proportional motion
double quasiStaticVelocityFactor(double phiBefore, double phiAfter, double velocity, double displacement) {
  if (phiAfter == phiBefore || !(displacement > 0)) return 0.0;
  return (phiAfter - phiBefore) * velocity / displacement;
}

int burstInterfacesOf(const Model& m) {
  const std::set<int> slices(m.precrackIfaceSlice.begin(), m.precrackIfaceSlice.end());
  const int perSlice = slices.empty() ? 1 : std::max<int>(1, m.precrackInterfaces / static_cast<int>(slices.size()));
  return kRateBurstSlices * perSlice;
}

void setRateMultiplierTarget(State& s, double target, long steps) {
  s.rateMultiplierTarget = target;
  s.rateRampSteps = target == s.rateMultiplier ? 0 : std::max(1L, steps);
}

// phi_{n+1} = phi_n + (target - phi_n) / k with k the ramp's steps left: equal increments, the target exactly
// at its last step.
double rateMultiplierAfterStep(const State& s) {
  if (s.rateRampSteps <= 0) return s.rateMultiplier;
  if (s.rateRampSteps == 1) return s.rateMultiplierTarget;
  return s.rateMultiplier + (s.rateMultiplierTarget - s.rateMultiplier) / static_cast<double>(s.rateRampSteps);
}

// phi(t_n + h) = phi_n + phi' h,  phi' = (phi_{n+1} - phi_n) / dt;  tau(t_n + h) = tau_n + h (phi_n + phi(h)) / 2
LoadingClock loadingClockAt(const State& s, double h, double dt) {
  LoadingClock c;
  c.phiRate = (rateMultiplierAfterStep(s) - s.rateMultiplier) / dt;
  c.phi = s.rateMultiplier + c.phiRate * h;
  c.tau = s.loadingTime + h * 0.5 * (s.rateMultiplier + c.phi);
  return c;
}

void advanceLoadingClock(const Loading& loading, double dt, State& s) {
  if (!loading.adaptive()) {  // off: tau is t (s.time already advanced), phi stays 1
    s.loadingTime = s.time;
    return;
  }
  const double next = rateMultiplierAfterStep(s);
  s.loadingTime += dt * 0.5 * (s.rateMultiplier + next);
  s.rateMultiplier = next;
  if (s.rateRampSteps > 0) --s.rateRampSteps;
}

}  // namespace enamel
