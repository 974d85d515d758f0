#pragma once
// The plain data a run is made of (docs/model.md), in four parts that change at different rates:
//   Model      the geometry (geometry.hpp): nodes, rod elements, interfaces; never changes
//   Materials  what the rods and interfaces are made of, how the specimen is damped and loaded; never changes
//   Operators  the assembled rod matrices K, M (rod deletions change them), DOF maps, interface adjacency
//   State      everything a time step changes; with the case, all that a checkpoint holds
// A scheme's own data (lumped mass, dt, its factorisation) lives in the scheme (integrators.hpp).
#include <array>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Dense>
#include <Eigen/Sparse>

#include "geometry/cohesive.hpp"
#include "geometry/geometry.hpp"
#include "laws/beam.hpp"
#include "laws/cohesive_law.hpp"

namespace enamel {

using VecX = Eigen::VectorXd;
using SpMat = Eigen::SparseMatrix<double>;

/// Graded velocity loading on the top and bottom boundary rows (docs/solver.md):
///   u_y = +/- U(t) (1 - x / w_s) (Grips, below: the default profile),  U' = v_app r(t),
///   r(t) = (1 - cos(pi t / T_r)) / 2 for t < T_r, then 1.
/// With an adaptive rate (rateAdaptMax > 1, loading_rate.hpp) the argument is the loading clock tau, not t.
struct Loading {
  double vApp = 0;      // peak applied velocity at the cracked edge
  double rampTime = 0;  // T_r
  double rateAdaptMax = 1;  // case key rate_adapt_max: the largest rate multiplier phi (1: off, tau = t)
  bool adaptive() const { return rateAdaptMax > 1; }
  double displacement(double t) const;
  double velocity(double t) const;
  double acceleration(double t) const;
  /// The time t >= 0 at which displacement(t) = U (U >= 0): closed form after the ramp, bisection within it
  /// (displacement is strictly increasing for t > 0).
  double timeOfDisplacement(double U) const;
};

/// The grips on the top (sign +1) and bottom (sign -1) rows (case keys grip_profile, grip_constraint; docs/model.md,
/// Loading): u_y = shape(sign, x/w_s) U(t) with
///   toRightEdge (default):  shape = sign (1 - x/w_s)      v_app at the cracked edge x = 0, 0 at x = w_s
///   aboutCentre:            shape = sign (1 - 2 x/w_s)    the face turned about its centre: +/-v_app at x = 0,
///                                                          -/+v_app at x = w_s
/// and slope = d shape / d(x/w_s); holdUx: u_x = 0 on the same nodes too (otherwise u_x and the rotations are free).
struct Grips {
  enum class Profile { toRightEdge, aboutCentre };
  Profile profile = Profile::toRightEdge;
  bool holdUx = false;
  double shape(double sign, double xOverWs) const {
    return profile == Profile::toRightEdge ? sign * (1.0 - xOverWs) : sign * (1.0 - 2.0 * xOverWs);
  }
  double slope(double sign) const { return profile == Profile::toRightEdge ? -sign : -2.0 * sign; }
};

/// Set up once from the case; a run never changes it.
struct Materials {
  beam::Section section;
  cohesive::Law law;
  std::vector<double> beamStrength;  // sigma_ru per rod element
  bool rodsBreakable = true;
  DeletionRule deletionRule = DeletionRule::most_overloaded;  // case key deletion_rule
  RodStress rodStress = RodStress::axial_bending;  // case key rod_stress
  // per element class Model::beamClass (ply: all rods of a ply share one orientation; and span): K_local T
  // (u_e -> local end forces), and the global element stiffness, consistent mass and lumped mass
  std::vector<beam::Mat12> beamLocalForceOperator, beamK, beamMc, beamMl;
  // per class: the rows beam::kStressRows of beamLocalForceOperator, all that the stress check needs
  std::vector<beam::StressOperator> beamStressOperator;
  // per class: beam::stressChangeBound of beamStressOperator (stress per unit of max |u_i| change)
  std::vector<double> beamStressChangeBound;
  // per class: the row beam::kTorsionRow of beamLocalForceOperator (the torque; read by rod_stress = principal only)
  std::vector<Eigen::Matrix<double, 1, 12>> beamTorsionOperator;
  double omegaMaxElement = 0;        // largest beam-element frequency (consistent mass)
  double E_transverse = 0, c_d = 0;  // transverse modulus and wave speed
  double omegaMin = 0, dampA = 0, dampB = 0;  // Rayleigh: C = dampA M + dampB K
  Loading loading;
  Grips grips;
};

/// The assembled operators. K and M hold the rods only (interfaces are never assembled) and lose a rod
/// element's stiffness (and consistent-minus-lumped mass) when it is deleted.
struct Operators {
  SpMat K, M;
  // Prescribed DOFs (u_y of the boundary rows, then their u_x when Grips::holdUx) and their shape: u = shape *
  // U(t), shape = Grips::shape (default +/-(1 - x/w_s); 0 for u_x), and its slope d shape / d(x/w_s) (default
  // -1 on the top row, +1 on the bottom row; 0 for u_x), per DOF, because the shape's sign cannot tell the rows
  // apart where it is +/-0 (x = w_s; x = w_s/2 about the centre).
  std::vector<int> prescribedDofs;
  std::vector<double> prescribedShape;
  std::vector<double> prescribedSlope;
  std::vector<int> freeDofs;
  std::vector<int> dofToFree;                    // index into freeDofs; -1 for prescribed
  std::vector<std::array<int, 2>> cutBeamNodes;  // nodes of the rod elements cut by the pre-crack
  // Interface adjacency (node -> interface ends, in ascending interface order; the kernels add each
  // interface's wrench to its nodes in that order).
  std::vector<int> nodeIfaceStart, nodeIfaceList;  // CSR; entries are 2*iface + side (0 = A, 1 = B)
  // The slices (geometry.hpp numbers nodes slice by slice, and builds interfaces slice by slice): the nodes
  // of slice k are sliceNodeStart[k] .. sliceNodeStart[k+1] - 1, its interfaces likewise; an interface joins
  // two nodes of its own slice. The force kernels work slice by slice, on data that stays in cache.
  std::vector<int> sliceNodeStart, sliceIfaceStart;
  std::vector<cohesive::SliceInterface> ifacePacked;  // Model::ifaceGeom in the compact form the kernels read
  int maxNodesPerSlice = 0;
};

/// The adaptive rate's margin rule (loading_rate.hpp; case key rate_adapt_rule = margin): each element's
/// progress toward its failure event at one history row, and the loading clock tau then. A rod element's is its
/// stress / strength (the deletion check's ratio: deleted at 1), an interface's its effective separation /
/// delta_f (failed at 1); NaN once the element is deleted or failed. Empty (and tau NaN) until measured.
struct EventProgress {
  double loadingTime = NAN;
  std::vector<double> rods, interfaces;
};

/// The margin rule's forecast at one history row, in history rows at phi = 1 (loading_rate.hpp
/// forecastEvents): the rows until the first rod break and the first interface failure (+inf: no element's
/// progress rose; NaN: not forecast), and the loading the last interval covered in rows. Kept in State for the
/// next row's trend (not a history column: a run with the rule off writes main's history, bit for bit).
struct EventForecast {
  double rowsToRodBreak = NAN, rowsToInterfaceFailure = NAN;
  double rowsElapsed = NAN;  // the last interval's loading time / rowTime (its mean phi)
};

/// Everything that changes during a run (checkpointable: checkpoint.cpp lists every field once).
struct State {
  long step = 0;
  double time = 0;
  double appliedDisplacement = 0;      // U: u_y of the top row at the cracked edge
  // loading clock (loading_rate.hpp): dtau/dt = phi; U = U(tau). Off: tau = t, phi = 1.
  double loadingTime = 0;              // tau
  double rateMultiplier = 1;           // phi at t_n
  double rateMultiplierTarget = 1;     // the value phi ramps to, linearly ...
  long rateRampSteps = 0;              // ... over this many more steps (0: no ramp, phi constant)
  VecX q;                              // displacements/rotations at t_n (6 per node)
  VecX v, a;                           // velocities and accelerations at t_n (`paper`; `lumped`: v is the
                                       // initial velocity `initialise` starts from, a unused)
  VecX vHalf;                          // half-step velocity v_{n-1/2} (`lumped`; empty for `paper`)
  VecX reaction;                       // force the grips apply at each prescribed DOF (last step)
  std::vector<double> lambdaMax;       // per interface: largest effective separation reached
  // per interface, only when the law is not the same in every mode (shear_strength_ratio != 1; empty otherwise):
  // the lambdaMax up to which its dissipation is booked, and that dissipation per area (measurements.hpp
  // bookInterfaceDissipation: it then depends on the mode the interface failed in, not on lambdaMax alone)
  std::vector<double> lambdaMaxBooked, ifaceDissipation;
  std::vector<std::uint8_t> beamBroken;  // per rod element: deleted
  std::vector<int> deletionOrder;        // rod elements in the order they were deleted (K, M are rebuilt so)
  // energy accumulators (time integrals)
  double externalWork = 0;             // int F_reaction . v_prescribed dt
  double dampingWork = 0;              // int v . C v dt
  double rodFractureEnergy = 0;        // strain (and mass-lumping kinetic) energy released by deleted rods
  double lastExternalPower = 0;        // grip power where the last interval of externalWork ended
  int failedInterfaces = 0;            // at the last update of the interface history
  double crackAdvance = 0;             // Delta a (d)
  EventProgress lastProgress;          // the margin rule's progress at the last history row (empty otherwise)
  EventForecast lastForecast;          // ... and its forecast there (NaN otherwise)

  int brokenBeams() const { return static_cast<int>(deletionOrder.size()); }
};

}  // namespace enamel
