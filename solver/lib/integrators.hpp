#pragma once
// Time integrators. `paper` is the reference (paper eq. 12-18); fast schemes sit beside it behind the
// same small interface (simulation.hpp: Integrator) and are chosen by the case key `integrator`.
#include <memory>
#include <stdexcept>
#include <string>

#include "simulation.hpp"

namespace enamel {

/// A time step the integrator cannot run stably, or a factorisation that failed: the message says which.
struct IntegratorError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// The integrator named by sim.params.integrator. Throws IntegratorError when dt is above the stable limit.
std::unique_ptr<Integrator> makeIntegrator(Simulation& sim);

}  // namespace enamel
