#include "simulation/simulation.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "kernels/loading_rate.hpp"
#include "kernels/measurements.hpp"
#include "kernels/static_solve.hpp"
#include "simulation/setup.hpp"

#ifdef _OPENMP
#include <omp.h>
#endif

namespace enamel {

// The set-up, step by step (setup.hpp): each step builds one part of the plain data from the case and the
// parts before it.
Simulation::Simulation(const CaseParams& p) : params(p), model(buildModel(p)) {
  describeMaterials(p, materials);
  materials.beamStrength = drawRodStrengths(model, p);
  buildElementClasses(model, materials);
  assembleOperators(model, materials, ops);
  setWaveSpeedDampingAndLoading(p, model, materials);
  prescribeGrips(model, materials.grips, ops);
  indexInterfacesByNode(model, ops);
  indexSlices(model, ops);
  state = stateAtRest(model, ops);
  bookInterfaceDissipation(model, materials.law, state);  // sizes the account (shear_strength_ratio != 1 only)
  setThreadCount(p, model.numDofs());
  integrator = makeIntegrator(p, model, materials, ops);
  if (integrator->usesHalfStepVelocity()) state.vHalf = VecX::Zero(model.numDofs());
}

Simulation::~Simulation() = default;

int threadCount() {
#ifdef _OPENMP
  return omp_get_max_threads();
#else
  return 1;
#endif
}

void Simulation::solveStaticElastic(double U, bool* mechanism) {
  stressSchedule_ = StressCheckSchedule{};  // q is replaced: the next deletion check computes every element
  const SpMat Kt = assembleElasticStiffness(model, materials.beamK, &state.beamBroken, materials.law);
  std::vector<int> dofs = ops.prescribedDofs;
  std::vector<double> values;
  for (double sh : ops.prescribedShape) values.push_back(sh * U);
  const int anchor = model.bottomNodes[0];  // against rigid translation in x (unless the grips hold u_x) and z
  if (materials.grips.holdUx) {
    dofs.push_back(6 * anchor + 2);
    values.push_back(0.0);
  } else {
    dofs.insert(dofs.end(), {6 * anchor, 6 * anchor + 2});
    values.insert(values.end(), {0.0, 0.0});
  }
  state.q = solveStaticPrescribed(Kt, dofs, values, mechanism);
  state.v.setZero();
  state.a.setZero();
  state.vHalf.setZero();
  state.appliedDisplacement = U;
  const VecX f = Kt * state.q;
  for (std::size_t i = 0; i < ops.prescribedDofs.size(); ++i) state.reaction[i] = f[ops.prescribedDofs[i]];
}

StaticStart Simulation::startFromStaticElastic(double fraction) {
  StaticStart st;
  st.fraction = fraction;
  solveStaticElastic(1.0, &st.mechanism);
  const VecX q1 = state.q, reaction1 = state.reaction;
  st.firstDamageDisplacement = computeFirstDamageDisplacement(model, materials, q1, state.beamBroken,
                                                              params.interfaces_breakable, st.limitedByRod);
  if (!(std::isfinite(st.firstDamageDisplacement) && st.firstDamageDisplacement > 0))
    throw IntegratorError("static_start = " + std::to_string(fraction) +
                          ": no interface opens and no rod element is stressed under the applied displacement "
                          "(first-damage displacement U_c = " + std::to_string(st.firstDamageDisplacement) +
                          "): there is no elastic stage to skip; use static_start = 0");
  st.displacement = fraction * st.firstDamageDisplacement;
  st.time = materials.loading.timeOfDisplacement(st.displacement);
  setQuasiStaticState(ops, materials.loading, q1, reaction1, st.displacement, st.time, state);
  // each interface's history at its current (elastic) separation (recorded only near delta0: cohesive_law.hpp)
  VecX f;
  state.failedInterfaces = computeForcesForInterfaces(model, materials.law, ops, state.q, state.lambdaMax, true, f);
  integrator->initialise(model, materials, ops, state);
  bookInterfaceDissipation(model, materials.law, state);
  // the grips did the work the specimen holds (quasi-statically: no damping work is booked for the skipped stage)
  state.externalWork = strainEnergyOfBeams() + strainEnergyOfInterfaces() + integrator->kineticEnergy(ops, state);
  return st;
}

/// rate_adapt_velocity = quasi_static: phi went from phiBefore to phi_{n+1} over the step just taken, so the free
/// nodes' velocity gets (phi_{n+1} - phiBefore) U'(tau_{n+1})/U q_{n+1} (quasiStaticVelocityFactor), and the
/// kinetic energy this adds is booked to the external work (the loading's impulse: the balance stays closed).
void Simulation::followRateChange(double phiBefore) {
  const double c = quasiStaticVelocityFactor(phiBefore, state.rateMultiplier, materials.loading.velocity(state.loadingTime),
                                             state.appliedDisplacement);
  if (c != 0.0) state.externalWork += integrator->addToFreeVelocities(ops, state, c);
}

/// One time step: the scheme's step; book the interfaces' dissipation; check the rods' stresses and delete the
/// overloaded ones; measure the crack when something broke. Each lap books the calls before it to their phase.
void Simulation::step() {
  PhaseLaps laps(timers_);
  const int failedBefore = state.failedInterfaces;
  const double phiBefore = state.rateMultiplier;
  integrator->advance(model, materials, ops, state);
  if (params.rate_adapt_velocity == RateAdaptVelocity::quasi_static) followRateChange(phiBefore);
  laps.lap(StepPhase::Advance);
  bookInterfaceDissipation(model, materials.law, state);
  laps.lap(StepPhase::InterfaceDissipation);
  checkRodStresses();
  laps.lap(StepPhase::DeletionCheck);
  const int deleted = deleteOverloadedBeams();
  laps.lap(StepPhase::Deletions);
  if (deleted > 0 || state.failedInterfaces != failedBefore) state.crackAdvance = measureCrackAdvance();
  laps.lap(StepPhase::CrackMeasure);
  if (timers_) ++timers_->steps;
}

void Simulation::setTimers(StepTimers* timers) {
  timers_ = timers;
  integrator->setTimers(timers);
}

namespace {

// Deletion rule (docs/model.md), independent of element order and thread count:
//  "most_overloaded": the element(s) with the largest stress ratio >= 1, ties within 1e-9 relative
//                     (mirror-symmetric rods) together; the rest are re-evaluated next step.
//  "all":             every element with ratio >= 1.
// `worst` is the largest ratio (StressCheckSchedule::largestRatio: the deletion check's, exact whenever it is >= 1).
std::vector<int> findOverloadedBeams(const std::vector<double>& ratio, const std::vector<std::uint8_t>& beamBroken,
                                     DeletionRule rule, double worst) {
  if (!(worst >= 1.0)) return {};
  const double threshold = rule == DeletionRule::all ? 1.0 : worst * (1.0 - 1e-9);
  std::vector<int> overloaded;
  for (std::size_t e = 0; e < ratio.size(); ++e)
    if (!beamBroken[e] && ratio[e] >= threshold) overloaded.push_back(static_cast<int>(e));
  return overloaded;
}

// Book the energy a deleted rod element releases as rod fracture energy: its strain energy 1/2 u^T K_e u,
// and with a consistent mass the kinetic energy of the mass lumping 1/2 v^T (M_e,consistent - M_e,lumped) v.
void bookEnergyOfDeletedBeam(const Model& m, const Materials& mat, int e, bool consistentMass, State& s) {
  const int a = m.beamNodes[e][0], b = m.beamNodes[e][1];
  const int c = m.beamClass(e);
  const beam::Vec12 u = gatherElement(s.q, a, b), v = gatherElement(s.v, a, b);
  s.rodFractureEnergy += 0.5 * u.dot(mat.beamK[c] * u);
  if (consistentMass) s.rodFractureEnergy += 0.5 * v.dot((mat.beamMc[c] - mat.beamMl[c]) * v);
}

}  // namespace

// A deleted element's stiffness (and its stiffness damping) is removed; its consistent mass is replaced by
// the lumped mass of the same element, so no material mass vanishes and no node is left massless (the paper
// subtracts M_e, eq. 17; see docs/model.md, departures). The energy it held is booked as rod fracture energy.
void Simulation::checkRodStresses() {
  if (!materials.rodsBreakable) return;
  checkStressRatiosForBeams(model, materials, state.q, state.beamBroken, state.step, integrator->lastStepMoveBound(),
                            integrator->lastStepMoveBoundsOfSlices(), stressSchedule_, beamStressRatio_);
}

int Simulation::deleteOverloadedBeams() {
  lastDeleted.clear();
  if (!materials.rodsBreakable) return 0;
  lastDeleted =
      findOverloadedBeams(beamStressRatio_, state.beamBroken, materials.deletionRule, stressSchedule_.largestRatio);
  if (lastDeleted.empty()) return 0;
  for (int e : lastDeleted) {
    bookEnergyOfDeletedBeam(model, materials, e, integrator->usesConsistentMass(), state);
    removeBeamFromMatrices(model, materials, e, ops);
    state.beamBroken[e] = 1;
    state.deletionOrder.push_back(e);
  }
  integrator->updateOperators(ops);
  return static_cast<int>(lastDeleted.size());
}

void Simulation::replayDeletions() {
  for (int e : state.deletionOrder) removeBeamFromMatrices(model, materials, e, ops);
  if (!state.deletionOrder.empty()) integrator->updateOperators(ops);
}

// --- measurements: the free functions of measurements.hpp on this run's data ---------------------------
double Simulation::strainEnergyOfBeams() const { return enamel::strainEnergyOfBeams(ops, state); }
double Simulation::strainEnergyOfInterfaces() const {
  return enamel::strainEnergyOfInterfaces(model, materials.law, state);
}
double Simulation::fractureEnergyOfInterfaces() const {
  return enamel::fractureEnergyOfInterfaces(model, materials.law, state);
}
int Simulation::countFailedInterfaces() const { return enamel::countFailedInterfaces(materials.law, state); }
int Simulation::countInelasticInterfaces() const { return enamel::countInelasticInterfaces(materials.law, state); }
double Simulation::inelasticReach() const { return enamel::inelasticReach(model, materials.law, state); }
double Simulation::inelasticInterfaceReach() const {
  return enamel::inelasticInterfaceReach(model, materials.law, state);
}
double Simulation::brokenRodReach() const { return enamel::brokenRodReach(model, state); }
double Simulation::computeJ() const { return enamel::computeJ(model, materials, ops, state); }
double Simulation::measureCrackAdvance() const { return enamel::measureCrackAdvance(model, materials.law, state); }

Measurement Simulation::measure() const {
  Measurement r;
  r.step = state.step;
  r.time = state.time;
  r.appliedDisplacement = state.appliedDisplacement;
  r.rateMultiplier = state.rateMultiplier;
  r.J = computeJ();
  r.crackAdvance = state.crackAdvance;
  r.kinetic = integrator->kineticEnergy(ops, state);
  // beyond the quasi-static motion q' = (U'/U) q; U' the grips' velocity now
  const double U = state.appliedDisplacement;
  const double rate = U > 0 ? computeGripVelocity(materials.loading, state, 0.0, integrator->timeStep()) / U : 0.0;
  r.kineticBeyond = integrator->kineticEnergyBeyond(ops, state, rate);
  r.strainBeams = strainEnergyOfBeams();
  r.strainInterfaces = strainEnergyOfInterfaces();
  r.damping = state.dampingWork;
  r.fracture = fractureEnergyOfInterfaces();
  r.rodFracture = state.rodFractureEnergy;
  r.external = state.externalWork;
  const double stored = r.kinetic + r.strainBeams + r.strainInterfaces + r.damping + r.fracture + r.rodFracture;
  r.balanceError = energyBalanceError(r.external, stored, balanceWorkFloor(params.Gamma(), model.B));
  r.brokenBeams = state.brokenBeams();
  r.failedInterfaces = countFailedInterfaces();
  r.inelasticInterfaces = countInelasticInterfaces();
  r.kinkedInterfaces = measureCrackCluster(model, materials.law, state).offPlaneInterfaces;
  r.inelasticReach = inelasticReach();
  r.load = computeGripLoad(ops, state);
  return r;
}

}  // namespace enamel
