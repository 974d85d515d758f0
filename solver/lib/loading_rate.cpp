#include "loading_rate.hpp"

#include <algorithm>
#include <set>

namespace enamel {

// rho = kinetic / strain; lower on a deletion or rho > rho_hi, raise when rho < rho_lo and quiet, else hold.
double nextRateMultiplier(double phi, double phiMax, const RateControlInput& in) {
  const bool deleted = in.rodsDeleted > 0;
  const bool burst = in.interfacesFailed > in.burstInterfaces;
  if (deleted) return std::max(1.0, kRateLower * phi);
  if (!(in.strain > 0)) return phi;  // no rho yet
  const double rho = in.kinetic / in.strain;
  if (rho > kRateRhoHigh) return std::max(1.0, kRateLower * phi);
  if (rho < kRateRhoLow && !burst) return std::min(phiMax, kRateRaise * phi);
  return phi;
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
