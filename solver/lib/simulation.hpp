#pragma once
// The simulation: model + physics + state, the kernels that loop over one kind of thing, and the
// measurements (J at the outer boundary, crack advance, energy balance). DESIGN.md sections 3-5.
//
// State lives in plain arrays in one struct (State), which is all a checkpoint needs besides the case.
#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Dense>
#include <Eigen/Sparse>

#include "beam.hpp"
#include "case_params.hpp"
#include "cohesive.hpp"
#include "geometry.hpp"

namespace enamel {

using VecX = Eigen::VectorXd;
using SpMat = Eigen::SparseMatrix<double>;

/// Everything that changes during a run (checkpointable).
struct State {
  long step = 0;
  double time = 0;
  double appliedDisplacement = 0;      // U: u_y of the top row at the cracked edge
  VecX q, v, a;                        // displacements/rotations, velocities, accelerations (6 per node)
  std::vector<double> lambdaMax;       // per interface: largest effective separation reached
  std::vector<std::uint8_t> beamBroken;  // per rod element: deleted
  std::vector<int> deletionOrder;        // rod elements in the order they were deleted (K, M are rebuilt so)
  // energy accumulators (time integrals)
  double externalWork = 0;             // int F_reaction . v_prescribed dt
  double dampingWork = 0;              // int v . C v dt
  double rodFractureEnergy = 0;        // strain (and mass-lumping kinetic) energy released by deleted rods
  double lastExternalPower = 0;
  int brokenBeams = 0;
  int failedInterfaces = 0;
  double crackAdvance = 0;             // Delta a (d)
};

/// Graded velocity loading on the top and bottom boundary rows (DESIGN section 4):
///   u_y = +/- U(t) (1 - x / w_s),  U' = v_app r(t),  r(t) = (1 - cos(pi t / T_r)) / 2 for t < T_r, then 1.
struct Loading {
  double vApp = 0;      // peak applied velocity at the cracked edge
  double rampTime = 0;  // T_r
  double displacement(double t) const;
  double velocity(double t) const;
  double acceleration(double t) const;
};

/// One row of /history.
struct Measurement {
  long step = 0;
  double time = 0, appliedDisplacement = 0, J = 0, crackAdvance = 0;
  double kinetic = 0, strainBeams = 0, strainInterfaces = 0, damping = 0, fracture = 0, rodFracture = 0;
  double external = 0, balanceError = 0;
  int brokenBeams = 0, failedInterfaces = 0, inelasticInterfaces = 0;
  double load = 0;      // generalised force conjugate to U: sum of F_y * (+/-)(1 - x/w_s)
};

class Simulation;

/// Worker threads the force loops use (set from the case key `threads` when a Simulation is built).
int threadCount();

/// A time integrator: advances the state by one step. The paper scheme is the reference; others sit beside it.
class Integrator {
 public:
  virtual ~Integrator() = default;
  virtual std::string name() const = 0;
  virtual double timeStep() const = 0;
  /// Advance sim.state from t_n to t_n + dt (positions, boundary conditions, forces, accelerations,
  /// velocities, reactions at the prescribed DOFs, damping work).
  virtual void advance(Simulation& sim) = 0;
  /// Make the integrator's own state consistent with a given q, v at state.time (a run from rest needs
  /// nothing): `paper` solves for the accelerations, H a = -f_iface(q) - K q - C v; `lumped` turns v into
  /// the half-step velocity v_{-1/2} = v - dt/2 M^-1 (-f_iface(q) - K q - C v). Used for initial-value tests.
  virtual void initialise(Simulation& sim) = 0;
  /// The rod elements just deleted (their K and M are already updated in sim).
  virtual void onBeamsDeleted(Simulation& sim) = 0;
  /// Kinetic energy 1/2 v^T M v with this integrator's mass matrix.
  virtual double kineticEnergy(const Simulation& sim) const = 0;
  /// Whether the integrator's mass is the consistent one (sim.M); false for lumped-mass schemes.
  virtual bool usesConsistentMass() const { return true; }
  /// One line on the scheme's own choices (mass scaling, damping), for the output's provenance.
  virtual std::string describe() const { return name(); }
};

class Simulation {
 public:
  explicit Simulation(const CaseParams& params);
  ~Simulation();

  // --- what was set up ---
  CaseParams params;
  Model model;
  beam::Section section;
  cohesive::Law law;
  std::vector<double> beamStrength;  // sigma_ru per rod element
  double E_transverse = 0, c_d = 0;  // measured transverse modulus and wave speed
  double omegaMin = 0, dampA = 0, dampB = 0;  // Rayleigh: C = dampA M + dampB K
  double omegaMaxElement = 0;        // largest beam-element frequency (consistent mass)
  double addedRotaryInertia = 0;     // rotary inertia added by a lumped scheme, as a fraction of the physical one
  Loading loading;
  std::vector<beam::Mat12> beamLocalForceOperator;  // per ply: K_local T (u_e -> local end forces)
  std::vector<beam::Mat12> beamK, beamMc, beamMl;   // per ply: global element stiffness / consistent / lumped mass

  // Rod matrices (rods only: interfaces are never assembled). Updated when rod elements are deleted.
  SpMat K, M;
  // Prescribed DOFs (u_y of the boundary rows) and their shape: u = sign * U(t) * (1 - x/w_s).
  std::vector<int> prescribedDofs;
  std::vector<double> prescribedShape;
  std::vector<int> freeDofs;
  std::vector<std::array<int, 2>> cutBeamNodes;  // nodes of the rod elements cut by the pre-crack
  std::vector<int> dofToFree;  // -1 for prescribed
  // Interface adjacency (node -> interface ends) for a deterministic gather of interface forces.
  std::vector<int> nodeIfaceStart, nodeIfaceList;  // CSR; entries are 2*iface + side (0 = A, 1 = B)

  State state;
  std::unique_ptr<Integrator> integrator;
  VecX reaction;                 // force applied by the grips at each prescribed DOF (last step)
  std::vector<int> lastDeleted;  // rod elements deleted in the last step
  std::string deletionRule;
  std::vector<cohesive::Vec3> ifaceForceOnB;  // scratch: per-interface force on node B, before the gather
  std::vector<double> beamStressRatio;              // scratch: sigma / sigma_ru per rod element

  // --- kernels (loops over one kind of thing) ---
  /// f_iface (eq. 8): internal force vector of all interfaces for displacements q; updates lambdaMax when
  /// `update` (a trial evaluation leaves the history untouched). Forces are gathered per node in a fixed
  /// order, so the result does not depend on the thread count.
  void computeForcesForInterfaces(const VecX& q, VecX& f, bool update);
  /// Rod stress ratio sigma / sigma_ru for every intact rod element.
  void computeStressRatiosForBeams(const VecX& q, std::vector<double>& ratio) const;
  /// Delete the rod elements whose stress reached their strength (rule: deletion_rule). Returns how many.
  int deleteOverloadedBeams();
  /// After a checkpoint restored state.deletionOrder into a freshly built simulation: remove those rod
  /// elements from K and M in the same order as the run did (so both are the same bit for bit) and let the
  /// integrator update once. Energies are not booked again (they are part of the restored state).
  void replayDeletions();
  /// Take rod element e out of K and M (its lumped mass stays at its nodes).
  void removeBeamFromMatrices(int e);
  /// Set q, v, a of the prescribed DOFs at time t.
  void applyBoundaryConditions(double t);
  /// Replace the state by the static elastic solution at applied displacement U (intact interfaces elastic,
  /// deleted rods left out) and set the reactions: the reference for J and compliance checks.
  void solveStaticElastic(double U);

  // --- measurements ---
  Measurement measure();
  double computeJ() const;                 // J at the outer boundary (DESIGN section 5)
  double measureCrackAdvance() const;      // Delta a of the cluster of failed elements touching the pre-crack
  double strainEnergyOfBeams() const;      // 1/2 q^T K q
  double strainEnergyOfInterfaces() const;
  double fractureEnergyOfInterfaces() const;
  int countFailedInterfaces() const;
  int countInelasticInterfaces() const;

  /// One time step, as its doc comment: advance the integrator (positions, boundary conditions, forces for
  /// beams and interfaces, accelerations, velocities), delete overloaded rods, track the crack.
  void step();

  std::vector<std::uint8_t> beamBrokenMask() const { return state.beamBroken; }
};

/// Measure E_transverse (modulus in the loading direction y) with the model itself: a static uniaxial
/// stretch of an uncracked block of the same microstructure, rods plus elastic interfaces, top and bottom
/// rows displaced by +/- delta/2, everything else free (one node fixed in x and z against rigid motion).
double measureTransverseModulus(const CaseParams& p, double* blockStrain = nullptr);

/// Static solution of K u = 0 with u prescribed (= values) at `dofs` (CHOLMOD on the free partition).
VecX solveStaticPrescribed(const SpMat& K, const std::vector<int>& dofs, const std::vector<double>& values);

}  // namespace enamel
