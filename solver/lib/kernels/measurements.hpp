#pragma once
// The measurements of a run, as free functions over its plain data (state.hpp): J at the outer boundary, the
// crack advance, the energies, the counts of failed and inelastic interfaces, how far the inelastic zone
// reaches. None changes anything (but bookInterfaceDissipation, the interfaces' dissipation account); Simulation::measure gathers them into one /history row. docs/model.md
// (Loading, damping, measurements) states each.
#include "data/state.hpp"

namespace enamel {

/// 1/2 q^T K q: the strain energy of the intact rod elements.
double strainEnergyOfBeams(const Operators& ops, const State& s);
/// Strain energy the interfaces hold (summed in a fixed order: independent of the thread count).
double strainEnergyOfInterfaces(const Model& m, const cohesive::Law& law, const State& s);
/// Energy the interfaces dissipated (their damage: Gamma_i per area once failed in normal opening; with
/// shear_strength_ratio = beta != 1 the booked State::ifaceDissipation, beta^2 Gamma_i per area once failed in
/// pure shear).
double fractureEnergyOfInterfaces(const Model& m, const cohesive::Law& law, const State& s);
/// With a law that is not the same in every mode (shear_strength_ratio != 1) only, and the one function here
/// that changes its State: books each interface's dissipation since the last call, as
/// cohesive::dissipationIncrement at its current opening from State::lambdaMaxBooked to its lambdaMax (called
/// after every step: the mode factor is then that of the step that moved lambdaMax). Nothing at beta = 1.
void bookInterfaceDissipation(const Model& m, const cohesive::Law& law, State& s);
int countFailedInterfaces(const cohesive::Law& law, const State& s);     // separation past delta_f
int countInelasticInterfaces(const cohesive::Law& law, const State& s);  // separation past delta0

/// How far from the crack plane (|y - y_crack|, at the midpoint of the element's nodes' reference positions)
/// the interfaces past delta0 reach, the deleted rod elements reach, and the larger of the two (0 while
/// everything is elastic).
double inelasticInterfaceReach(const Model& m, const cohesive::Law& law, const State& s);
double brokenRodReach(const Model& m, const State& s);
double inelasticReach(const Model& m, const cohesive::Law& law, const State& s);

/// Each element's progress toward its failure event (EventProgress, state.hpp; the adaptive rate's margin
/// rule): a rod element's stress / strength as the deletion check computes it (computeStressRatiosForBeams; no
/// rods when they do not break), an interface's effective separation / delta_f (cohesive::effectiveSeparation
/// of the law at its present opening: what lambdaMax must reach for it to fail); NaN once deleted or failed.
/// The loading clock is s.loadingTime.
EventProgress measureEventProgress(const Model& m, const Materials& mat, const State& s);

/// The loaded faces' term of J before the 1/B: sum over the prescribed DOFs of F_y du_y/dx, with F_y the
/// force the grip applies and du_y/dx = ops.prescribedSlope x U / w_s (-U/w_s on the top row, +U/w_s on the
/// bottom row, also at x = w_s where the shape value is +/-0).
double sumGripForceTimesSlope(const Model& m, const Operators& ops, const State& s);
/// Strain energy per unit length in x at a free face: side 0 the left face (the elements starting in slice
/// `slice`), side 1 the right face (those ending there). Rod elements of the first segment over h_e,
/// interfaces of the end slice over their tributary h_e / 2; in a reduced far field an element spanning n
/// slices over n h_e and an interface over the length along x it stands for (area / edge length).
double faceEnergyDensity(const Model& m, const Materials& mat, const State& s, int slice, int side);
/// J at the outer boundary, per unit thickness B: J = (1/B) [ -sum F_y du_y/dx + W_right - W_left ].
double computeJ(const Model& m, const Materials& mat, const Operators& ops, const State& s);

/// Delta_a: the connected cluster of failed interfaces and deleted rod elements that touches the pre-crack,
/// max x over it - a0_eff (projected on x; daughter cracks count once they join). Two elements are connected
/// when they touch the same rod in the same or adjacent slices, so the cluster follows a crack on any path:
/// through either ply and the interlayers, kinked or deflected off the mid-plane.
double measureCrackAdvance(const Model& m, const cohesive::Law& law, const State& s);

/// The crack's cluster (failed interfaces and deleted rod elements connected to the pre-crack, docs/model.md):
/// its advance (as measureCrackAdvance) and how many of its failed interfaces join two rods on one side of the
/// crack plane: the kinks along the rods, which the paper sees form before any rod breaks (docs/results.md).
struct CrackCluster {
  double advance = 0;          // Delta a (d)
  int offPlaneInterfaces = 0;  // failed interfaces of the cluster off the crack plane
};
CrackCluster measureCrackCluster(const Model& m, const cohesive::Law& law, const State& s);

/// The generalised force conjugate to U: sum of F_y x shape over the prescribed DOFs.
double computeGripLoad(const Operators& ops, const State& s);

/// The work floor of the energy balance error: 0.1 Gamma_i B d, the work to open a tenth of one d of crack
/// across the z-period B. Until the external work exceeds it, the error is measured against it.
double balanceWorkFloor(double Gamma, double B);

/// The energy balance error of a history row (/history/energy_balance_error, docs/solver.md): (external work -
/// stored - kinetic - dissipated) / max(|external work|, workFloor). Against the floor, the first rows of a run
/// (external work ~1e-10 of it) do not turn the round-off and the time discretisation of the work into errors of
/// order one; once the work exceeds the floor it is the relative error of the balance.
double energyBalanceError(double external, double storedKineticDissipated, double workFloor);

}  // namespace enamel
