#pragma once
// Kernels: loops over one kind of thing (interfaces, rod elements, prescribed DOFs) on plain data
// (state.hpp). No I/O. The time integrators (integrators.hpp) and the simulation (simulation.hpp) call them.
#include <vector>

#include "data/state.hpp"
#include "kernels/node_blocks.hpp"

namespace enamel {

/// The 12 DOFs (uA, thA, uB, thB) of the element between nodes a and b.
beam::Vec12 gatherElement(const VecX& q, int a, int b);

/// u_p = shape_p U(tau_n) at the prescribed DOFs, and s.appliedDisplacement = U(tau_n) (tau: the loading
/// clock, s.loadingTime; = t_n when the rate is not adaptive).
void prescribeDisplacements(const Operators& ops, const Loading& loading, State& s);
/// v_p = shape_p V at the prescribed DOFs of a velocity vector v.
void prescribeVelocities(const Operators& ops, double V, VecX& v);
/// The grips' velocity V at t_n + h: U'(t_n + h), or with an adaptive rate phi U'(tau) on the loading clock
/// (loading_rate.hpp; dt is the step over which phi is linear).
double computeGripVelocity(const Loading& loading, const State& s, double h, double dt);
/// q, v and a of the prescribed DOFs at t_n: U, U', U'' of t_n, or with an adaptive rate U(tau),
/// phi U'(tau), phi^2 U''(tau) + phi' U'(tau).
void applyBoundaryConditions(const Operators& ops, const Loading& loading, double dt, State& s);

/// The wrench (force, moment) that the interfaces of slice k exert on each of its nodes, into wrench[6 (node -
/// first node of the slice) + 0..5]: per interface its force on B (cohesive::computeInterfaceForceOnB of the
/// compact geometry) and the wrench on either side (cohesive::wrenchOnSide) added to its two nodes, in
/// ascending interface order (so nothing depends on the thread count). lambdaMax is updated only when
/// `update`. Returns the number of failed interfaces of the slice (with the history as updated, or as it
/// would be).
int addInterfaceWrenchesOfSlice(const Model& m, const cohesive::Law& law, const Operators& ops, int k,
                                const double* q, double* lambdaMax, bool update, double* wrench);
/// The local opening (n, t1, t2) of interface i at displacements q, in the general form (measurements and
/// set-up: energies, the static start's U_c; the step reads the compact form).
cohesive::Vec3 computeLocalOpening(const Model& m, const VecX& q, int i);
/// f_iface (eq. 8): internal force vector of all interfaces for displacements q, slice by slice: the forces of
/// a slice's interfaces and their wrench on each of its nodes (addInterfaceWrenchesOfSlice), f = -(that
/// wrench); f is resized to the DOFs. lambdaMax is updated only when `update` (a trial
/// evaluation leaves the history untouched). Returns the number of failed interfaces.
int computeForcesForInterfaces(const Model& m, const cohesive::Law& law, const Operators& ops, const VecX& q,
                               std::vector<double>& lambdaMax, bool update, VecX& f);

/// The lumped step's schedule of the interface law. An interface on the elastic branch (secantStiffness = k)
/// exerts cohesive::elasticForceOnB, linear in its DOFs; the law (cohesive::computeTraction) is needed only to
/// notice it leave its elastic track (cohesive_law.hpp), and it cannot while its effective separation lambda stays
/// below (1 - kInterfaceScheduleMargin) lambdaTrack (lambdaTrack = sqrt(kElasticTrack) delta0; lambda of the
/// mixed-mode law, cohesive::effectiveSeparation(law, .)). lambda moves by at most c |q change|_inf,
/// c = max(1, 1/beta) sqrt(3) (2 + |rA,y| + |rA,z| + |rB,y| + |rB,z|) (lambda is max(1, 1/beta)-Lipschitz in the
/// opening, whose components each move by at most their row's sum of |coefficients| times |q change|_inf): so
/// an interface whose lambda was computed when its slice's drift (the sum over steps of a bound on the move of the
/// slice's DOFs: an interface joins two nodes of its own slice) stood at D need not see the law before that drift
/// reaches D + ((1 - margin) lambdaTrack - lambda) / c. Every other
/// interface (due, or off the elastic branch) is evaluated by the law at every step, exactly as without the
/// schedule: the histories, and so which interfaces are elastic, are the same, and the force of an interface
/// depends only on q and its history (elasticForceOnB while elastic, the law's otherwise), never on the
/// schedule: a fresh schedule (a restart) gives the same numbers. Scratch, not part of State.
inline constexpr double kInterfaceScheduleMargin = 1e-4;
inline constexpr int kInterfaceChunk = 64;
struct InterfaceSchedule {
  std::vector<double> drift;  // per slice: bound on how far any DOF of its nodes moved since the schedule started
  bool allDue = false;        // this pass evaluates every interface (otherwise those with due <= their slice's drift)
  double largestRate = 0;     // max over interfaces of c
  std::vector<double> due;    // per interface: the drift from which the law must see it again
  // Each slice's interfaces in chunks of kInterfaceChunk consecutive ones (the last of a slice may be shorter): a
  // chunk with none due is skipped whole, without reading its interfaces, and a slice with none due is not visited.
  std::vector<int> sliceChunkStart;  // per slice k: its first chunk (sliceChunkStart[numSlices]: the number of chunks)
  std::vector<double> chunkDue;      // per chunk: the smallest due of its interfaces
  long visitedChunks = 0;            // chunks the last pass read (the sum of SliceCorrections::chunks)
  long evaluated = 0;         // interfaces the last pass evaluated by the law
};
/// Before a pass at displacements that moved by at most `moved` (max over DOFs; infinite: start afresh) since the
/// last one, and by at most sliceMoved[k] over the DOFs of slice k's nodes (empty: `moved` for every slice), with
/// max |q| = `largestValue`: a fresh schedule (every interface due) when it has none of the model's size or
/// `moved` is not finite; all due this pass (without restarting) when the round-off of an opening,
/// 32 eps c |q|_inf, could reach a quarter of the margin, kInterfaceScheduleMargin lambdaTrack / 4.
void advanceInterfaceSchedule(const Model& m, const cohesive::Law& law, const Operators& ops, double moved,
                              const std::vector<double>& sliceMoved, double largestValue, InterfaceSchedule& schedule);
/// The interfaces' elastic stiffness K_I in node blocks (groups kInterfaceGroups): the sum over interfaces of
/// cohesive::elasticStiffness, so that K_I q is every interface's elastic force (f_iface of interfaces on the
/// elastic branch: cohesive::elasticForceOnB, up to round-off). Block row R: its diagonal block (the interfaces
/// of node R, summed in ascending interface order from +0) and one block per node it shares an interface with
/// (ascending columns). Each distinct block is stored once: the geometry repeats from slice to slice.
inline constexpr double kInterfaceBlockTolerance = 0x1p-40;  // ~9.1e-13
NodeBlockMatrix elasticInterfaceBlocks(const Model& m, const cohesive::Law& law, const Operators& ops);

/// The lumped step's interface pass with the schedule, for a step that applies every interface's elastic force
/// as K_I q (elasticInterfaceBlocks) in its node rows: into wrench, per node of slice k, what the law adds to
/// that, the wrench of (law's force - elastic force) of each interface off the elastic branch. An interface
/// not due adds nothing (it is elastic); a due one is evaluated by the law (lambdaMax updated), adds its
/// difference when it is off the elastic branch (nothing while on it), and gets its next due drift. A chunk
/// none of whose interfaces is due (schedule.chunkDue) is not read; a slice with no chunk read gets no wrench
/// written. Adds the interfaces evaluated to `evaluated`.
struct SliceCorrections {
  int failed = 0;       // failed interfaces of the slice
  bool wrench = false;  // the wrench was written (otherwise it is zero, and left as it was)
  int chunks = 0;       // chunks of interfaces read (InterfaceSchedule::chunkDue)
};
SliceCorrections addInterfaceCorrectionsOfSliceScheduled(const Model& m, const cohesive::Law& law, const Operators& ops, int k,
                                            const double* q, double* lambdaMax, InterfaceSchedule& schedule,
                                            double* wrench, long& evaluated);
/// Stress of rod element e for the brittle check (units of E_r), as case key rod_stress defines it (default
/// beam::maxTensileStress of its local end forces).
double computeStressOfBeam(const Model& m, const Materials& mat, const VecX& q, int e);
/// Stress ratio sigma / sigma_ru of every intact rod element (0 for deleted ones): the deletion check.
void computeStressRatiosForBeams(const Model& m, const Materials& mat, const VecX& q,
                                 const std::vector<std::uint8_t>& beamBroken, std::vector<double>& ratio);

/// The deletion check's schedule (rod_stress axial_bending): which rod elements need their stress computed.
/// An element whose ratio r = sigma/sigma_ru was computed when its drift stood at D cannot reach
/// 1 - kStressScheduleMargin while its drift stays below D + (1 - kStressScheduleMargin - r) sigma_ru / L
/// (L = Materials::beamStressChangeBound of its ply): until then it cannot break, and its stress is not computed.
/// An element's drift is the sum over steps of a bound on how far its 12 DOFs moved: for an element between
/// slices k and k + 1, that of the pair (the larger of the two slices' moves); for any other (one spanning
/// several slices in a reduced far field), or when the scheme gives no slice's move, the largest move of any DOF.
/// Scratch, not part of State: a fresh schedule computes every element once, so a restarted run deletes the same
/// elements as the run it continues.
inline constexpr double kStressScheduleMargin = 1e-4;
inline constexpr int kStressCheckChunk = 64;
struct StressCheckSchedule {
  long step = -1;          // the step of the last check (-1: none); a check at any other step than the next starts afresh
  double drift = 0;        // bound on how far any DOF moved since the schedule started
  std::vector<double> pairDrift;  // per slice k: bound on how far any DOF of slices k and k + 1 moved since then
  std::vector<int> pairOf; // per rod element: the k of its slices k, k + 1 (-1: it follows `drift`)
  std::vector<double> due; // per rod element: its drift from which its stress must be computed again
  // Chunks of kStressCheckChunk consecutive elements (elements are in the order of their first node, so a chunk
  // spans one or two pairs of slices): a chunk whose smallest due is above the largest drift of its elements is
  // skipped whole, without reading its elements.
  std::vector<double> chunkDue;      // per chunk: the smallest due of its intact elements (when last visited)
  std::vector<int> chunkPairs;       // per chunk: the first and last pair its elements follow (2 entries; first >
                                     // last: none)
  std::vector<std::uint8_t> chunkFollowsDrift;  // per chunk: some element follows `drift`
  long computed = 0;       // elements computed at the last check
  long visitedChunks = 0;  // chunks read at the last check
  double largestRatio = 0; // the largest ratio computed at the last check: an element at 1 - kStressScheduleMargin
                           // or above is computed at every check, so no ratio reaches 1 while this stays below
};

/// The deletion check at step `step`, the displacements having moved by at most `moved` (max over DOFs; infinite
/// when the scheme gives no bound) since the check at step - 1, and by at most sliceMoved[k] over the DOFs of
/// slice k's nodes (empty where the scheme gives only `moved`): ratio[e] = sigma / sigma_ru of every intact rod
/// element that could have reached 1 - kStressScheduleMargin (and of all of them when the schedule starts
/// afresh, `moved` is infinite, or rod_stress is not axial_bending); an element not computed keeps its last
/// ratio, below 1 - kStressScheduleMargin as its present one is; 0 for deleted ones. The same elements pass 1
/// as with computeStressRatiosForBeams, with the same ratios.
void checkStressRatiosForBeams(const Model& m, const Materials& mat, const VecX& q,
                               const std::vector<std::uint8_t>& beamBroken, long step, double moved,
                               const std::vector<double>& sliceMoved, StressCheckSchedule& schedule,
                               std::vector<double>& ratio);

/// Take rod element e out of K (its stiffness) and M (consistent minus lumped mass: its lumped mass stays).
void removeBeamFromMatrices(const Model& m, const Materials& mat, int e, Operators& ops);

}  // namespace enamel
