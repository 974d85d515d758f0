#pragma once
// Pieces of a step that every scheme uses (the clock, the grips' entries, their power and work): inline, so that
// each scheme's step compiles them as its own.
#include "data/state.hpp"
#include "kernels/loading_rate.hpp"

namespace enamel {

// t_{n+1} = t_n + dt, n + 1, and the loading clock tau_{n+1} (loading_rate.hpp)
inline void advanceClock(const Loading& loading, State& s, double dt) {
  s.time += dt;
  ++s.step;
  advanceLoadingClock(loading, dt, s);
}

// The prescribed DOFs' entries of a vector indexed by DOF.
inline void gatherGrips(const Operators& ops, const VecX& x, VecX& atGrips) {
  atGrips.resize(static_cast<Eigen::Index>(ops.prescribedDofs.size()));
  for (std::size_t i = 0; i < ops.prescribedDofs.size(); ++i) atGrips[i] = x[ops.prescribedDofs[i]];
}

// P = sum_p R_p v_p: the power of the grips (summed in the order of the prescribed DOFs)
inline double computeGripPower(const VecX& reaction, const VecX& gripVelocity) {
  double power = 0;
  for (Eigen::Index i = 0; i < reaction.size(); ++i) power += reaction[i] * gripVelocity[i];
  return power;
}

// W_ext += dt/2 (P_prev + P): trapezoid rule over the interval that ends where P was taken (none when
// `intervalEnds` is false: the first reactions of `lumped`, at t_0); P is kept for the next interval.
inline void addWorkOfGrips(State& s, double power, double dt, bool intervalEnds = true) {
  if (intervalEnds) s.externalWork += 0.5 * dt * (s.lastExternalPower + power);
  s.lastExternalPower = power;
}

}  // namespace enamel
