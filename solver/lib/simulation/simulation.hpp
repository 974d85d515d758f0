#pragma once
// The simulation: the plain data of a run (state.hpp), built by the named set-up steps of setup.hpp, and its
// integrator; the level above a scheme's step (rod deletions, crack tracking) and the static elastic start.
// The measurements are free functions over the plain data (measurements.hpp); the members below that name
// them apply them to this run's data.
#include <cmath>
#include <cstdint>
#include <memory>
#include <vector>

#include "case/case_params.hpp"
#include "data/state.hpp"
#include "data/step_timers.hpp"
#include "integrators/integrators.hpp"
#include "kernels/kernels.hpp"
#include "kernels/static_solve.hpp"  // solveStaticPrescribed, computeFirstDamageDisplacement
#include "simulation/setup.hpp"  // measureTransverseModulus

namespace enamel {

/// One row of /history (output.cpp: historyColumns() names each field once).
struct Measurement {
  long step = 0;
  double time = 0, appliedDisplacement = 0, J = 0, crackAdvance = 0;
  double kinetic = 0, kineticBeyond = 0, strainBeams = 0, strainInterfaces = 0, damping = 0, fracture = 0, rodFracture = 0;
  double external = 0, balanceError = 0;
  int brokenBeams = 0, failedInterfaces = 0, inelasticInterfaces = 0;
  int kinkedInterfaces = 0;  // failed interfaces of the crack's cluster off the crack plane (CrackCluster)
  double load = 0;      // generalised force conjugate to U: sum of F_y * (+/-)(1 - x/w_s)
  double rateMultiplier = 1;  // phi of the adaptive loading rate (loading_rate.hpp; 1 when off)
  double inelasticReach = 0;  // largest |y - y_crack| of an inelastic interface or broken rod element (d)
};

/// What a static elastic start (case key static_start, Simulation::startFromStaticElastic) did; plain data,
/// kept in the run record (output /meta, checkpoint). fraction = 0: the run started from rest.
struct StaticStart {
  double fraction = 0;                   // case key static_start
  double firstDamageDisplacement = NAN;  // U_c: applied displacement at which the first interface reaches
                                         // delta0 or the first rod element its strength (static, linear)
  double displacement = 0;               // U* = fraction x U_c, where the run starts
  double time = 0;                       // t*: Loading::displacement(t*) = U*
  bool limitedByRod = false;             // U_c set by a rod element's strength (else by an interface)
  bool mechanism = false;                // the elastic stiffness was singular: a part free to move without
                                         // strain (solveStaticPrescribed) stayed where it was
  double solveSeconds = 0;               // wall time of the static solve and the start state (set by the runner)
};

/// Worker threads the force loops use (set from the case key `threads` when a Simulation is built).
int threadCount();

/// A run's data (state.hpp) and its time integrator, built from a case; the level above a scheme's step
/// (rod deletions, crack tracking) and the measurements.
class Simulation {
 public:
  explicit Simulation(const CaseParams& params);
  ~Simulation();

  CaseParams params;
  Model model;
  Materials materials;
  Operators ops;
  State state;
  std::unique_ptr<Integrator> integrator;
  std::vector<int> lastDeleted;  // rod elements deleted in the last step

  /// One time step: the scheme's step (forces, velocities, positions, boundary conditions, the work of the
  /// grips, damping work), then book the interfaces' dissipation, check the rods' stresses, delete overloaded
  /// rods and measure the crack when something broke.
  void step();
  /// The deletion check: each rod element's stress ratio sigma / sigma_ru as the schedule requires it
  /// (kernels.hpp checkStressRatiosForBeams; nothing when rods are unbreakable).
  void checkRodStresses();
  /// Delete the rod elements whose stress ratio at the last check reached 1 (rule: deletion_rule), book the
  /// energy they held, and let the integrator update. Returns how many.
  int deleteOverloadedBeams();
  /// Where step() books the time of its phases and its scheme's (step_timers.hpp: `enamel-dem profile`);
  /// null, the default: nowhere. The timers must outlive the steps they time.
  void setTimers(StepTimers* timers);
  /// After a checkpoint restored state.deletionOrder into a freshly built simulation: remove those rod
  /// elements from K and M in the same order as the run did (so both are the same bit for bit) and let the
  /// integrator update once. Energies are not booked again (they are part of the restored state).
  void replayDeletions();
  /// Replace the state by the static elastic solution at applied displacement U (intact interfaces elastic,
  /// deleted rods left out) and set the reactions: the reference for J and compliance checks.
  void solveStaticElastic(double U, bool* mechanism = nullptr);
  /// Static elastic start (case key static_start = fraction > 0): the static elastic solution q1 at U = 1,
  /// U_c (computeFirstDamageDisplacement), U* = fraction U_c, t* with U(t*) = U*; then the quasi-static state
  /// of the loading at t*: q = U* q1, v = U'(t*) q1, a = U''(t*) q1, time t*, each interface's history at its
  /// current separation, reactions U* K_t q1, external work = the energy the specimen then holds (strain and
  /// kinetic: what the grips did, quasi-statically), and the integrator initialised from it. step stays 0.
  /// Throws IntegratorError when U_c is not finite and positive (nothing opens: no damage to start before).
  StaticStart startFromStaticElastic(double fraction);

  // --- measurements (measurements.hpp) on this run's data ---
  Measurement measure() const;
  double computeJ() const;                 // J at the outer boundary (docs/model.md)
  double measureCrackAdvance() const;      // Delta a of the cluster of failed elements touching the pre-crack
  double strainEnergyOfBeams() const;      // 1/2 q^T K q
  double strainEnergyOfInterfaces() const;
  double fractureEnergyOfInterfaces() const;
  int countFailedInterfaces() const;
  int countInelasticInterfaces() const;
  double inelasticReach() const;           // the larger of the two below
  double inelasticInterfaceReach() const;  // interfaces past delta0
  double brokenRodReach() const;           // deleted rod elements
  /// The deletion check's schedule (its `computed` count: elements computed at the last step).
  const StressCheckSchedule& stressCheckSchedule() const { return stressSchedule_; }

 private:
  void followRateChange(double phiBefore);  // rate_adapt_velocity = quasi_static (simulation.cpp)
  std::vector<double> beamStressRatio_;  // scratch: sigma / sigma_ru per rod element
  StressCheckSchedule stressSchedule_;   // scratch: which rod elements the deletion check computes
  StepTimers* timers_ = nullptr;         // setTimers
};

}  // namespace enamel
