#pragma once
// Time integrators. `paper` is the reference (paper eq. 12-18); fast schemes sit beside it behind the same
// small interface, one scheme per file of solver/lib/integrators/, and are chosen by the case key `integrator`
// from the table of integratorRegistry(). A scheme keeps its own data (dt, its mass or
// factorisation, scratch); it is given the set-up data by const reference and the State by reference.
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "base/errors.hpp"  // IntegratorError, SolverError (kept here for the files that include them through this one)
#include "case/case_params.hpp"
#include "data/state.hpp"
#include "data/step_timers.hpp"
#include "kernels/kernels.hpp"  // InterfaceSchedule

namespace enamel {

/// A time integrator: advances the State by one step.
class Integrator {
 public:
  virtual ~Integrator() = default;
  virtual std::string name() const = 0;
  virtual double timeStep() const = 0;
  /// Advance s from t_n to t_n + dt, as the scheme's doc comment lists the step (integrators/newmark.cpp,
  /// integrators/lumped.cpp): forces,
  /// velocities, positions, boundary conditions, reactions and the work of the grips, damping work.
  virtual void advance(const Model& m, const Materials& mat, const Operators& ops, State& s) = 0;
  /// Make the scheme's own state consistent with a given q, v at s.time (a run from rest needs nothing):
  /// `paper` solves for the accelerations, H a = -f_iface(q) - K q - C v; `lumped` sets the half-step
  /// velocity vHalf = v_{-1/2} = v - dt/2 M^-1 (-f_iface(q) - K q - C v). Used for initial-value tests.
  virtual void initialise(const Model& m, const Materials& mat, const Operators& ops, State& s) = 0;
  /// K and M changed (rod elements deleted): update what the scheme derived from them.
  virtual void updateOperators(const Operators& ops) = 0;
  /// Kinetic energy 1/2 v^T M v with this scheme's mass matrix and velocity.
  virtual double kineticEnergy(const Operators& ops, const State& s) const = 0;
  /// Kinetic energy of the motion beyond proportional loading: 1/2 w^T M w, w = v - rate q (rate = U'/U of the
  /// grips): what is left of the velocity when the quasi-static motion q' = (U'/U) q of a linear specimen is
  /// taken out (the adaptive loading rate's measure, loading_rate.hpp).
  virtual double kineticEnergyBeyond(const Operators& ops, const State& s, double rate) const = 0;
  /// Add c q to the free DOFs' velocity (the scheme's: v, or vHalf for a half-step scheme) and return the
  /// kinetic energy this adds, 1/2 (v + dv)^T M (v + dv) - 1/2 v^T M v with this scheme's mass (the adaptive
  /// rate's velocity correction, loading_rate.hpp quasiStaticVelocityFactor).
  virtual double addToFreeVelocities(const Operators& ops, State& s, double c) const = 0;
  /// Whether the scheme's mass is the consistent one (ops.M); false for lumped-mass schemes.
  virtual bool usesConsistentMass() const { return true; }
  /// Whether the scheme's velocity is the half-step one (State::vHalf) rather than v_n (State::v).
  virtual bool usesHalfStepVelocity() const { return false; }
  /// Rotary inertia the scheme added, as a fraction of the physical one (reported in the output).
  virtual double addedRotaryInertia() const { return 0; }
  /// A bound on how far any DOF moved in the last step, max_i |q_i(t_{n+1}) - q_i(t_n)| (round-off included);
  /// infinite when the scheme gives none (then the deletion check computes every rod element).
  virtual double lastStepMoveBound() const { return INFINITY; }
  /// Per slice k, a bound on how far any DOF of its nodes moved in the last step (round-off included; each at
  /// most lastStepMoveBound); empty when the scheme gives only the global bound. The schedules follow each slice's
  /// own drift with it, so that where nothing moves nothing is computed.
  virtual const std::vector<double>& lastStepMoveBoundsOfSlices() const {
    static const std::vector<double> none;
    return none;
  }
  /// The schedule of the interface law the step keeps (`lumped`, kernels.hpp InterfaceSchedule; its `evaluated`:
  /// the last step's count); null when the scheme evaluates every interface at every step.
  virtual const InterfaceSchedule* interfaceSchedule() const { return nullptr; }
  /// One line on the scheme's own choices (mass scaling, damping), for the output's provenance.
  virtual std::string describe() const { return name(); }
  /// Where advance books the time of its phases (step_timers.hpp; null, the default: nowhere).
  void setTimers(StepTimers* timers) { timers_ = timers; }

 protected:
  StepTimers* timers_ = nullptr;
};

/// A scheme's factory: the scheme set up for these operators.
using IntegratorFactory = std::unique_ptr<Integrator> (*)(const CaseParams& p, const Model& m, const Materials& mat,
                                                          const Operators& ops);
/// The counts of a case's model that a scheme's cost estimate reads (estimateResources, simulation/resources.hpp:
/// from the case keys alone, before anything is built).
struct SchemeSizes {
  double nodes = 0;
  double dof = 0;
  double nodesPerSlice = 0;  // the bandwidth of a factor of M or K
};
/// A scheme's share of a run's costs: the peak resident memory of the model's data and the scheme's own (the
/// executable and the static start's factor are the estimate's), and one core's seconds per step.
struct SchemeCosts {
  double memoryBytes = 0;
  double secondsPerStep = 0;
};
/// A scheme's cost estimate: a pure function of the case and its sizes, measured on runs of the scheme (its file
/// gives the measurements).
using IntegratorCostEstimate = SchemeCosts (*)(const CaseParams& p, const SchemeSizes& sizes);
/// A row of the table of schemes: the `integrator` key's value that chooses it (its name: nameOf(scheme)), its
/// factory and its cost estimate (made before the scheme is built: enamel-dem info --estimate, the memory check).
struct IntegratorEntry {
  IntegratorScheme scheme;
  IntegratorFactory make;
  IntegratorCostEstimate estimateCosts;
};
/// Every scheme of this build, one row per enumerator of IntegratorScheme in its order (integrators/registry.cpp;
/// tests/cpp/test_integrators.cpp checks that they agree).
const std::vector<IntegratorEntry>& integratorRegistry();

/// The row of integratorRegistry() of this scheme; IntegratorError when the build has none.
const IntegratorEntry& integratorEntry(IntegratorScheme scheme);

/// The integrator named by p.integrator (its row of integratorRegistry()), set up for these operators. Throws
/// IntegratorError when no row has that name, when dt is above the stable limit; SolverError when a factorisation
/// fails.
std::unique_ptr<Integrator> makeIntegrator(const CaseParams& p, const Model& m, const Materials& mat,
                                           const Operators& ops);

}  // namespace enamel
