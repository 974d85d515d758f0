#pragma once
// Building a run's parts from a case: the named set-up steps of Simulation's constructor, each from the case
// and the parts built before it to one part of the plain data (state.hpp). docs/model.md states the model they
// build; docs/solver.md the loading and damping.
#include <vector>

#include "case/case_params.hpp"
#include "data/state.hpp"

namespace enamel {

GeometryParams geometryOf(const CaseParams& p);
beam::Section sectionOf(const CaseParams& p);
/// The interface law (unbreakable interfaces, for verification runs, keep the elastic branch however far
/// they open).
cohesive::Law lawOf(const CaseParams& p);
/// The grips' profile and constraint (case keys grip_profile, grip_constraint).
Grips gripsOf(const CaseParams& p);

/// The crossply of the case, with its reduced far field when far_field_slices > 1.
Model buildModel(const CaseParams& p);
/// Section, law, deletion rule, rod stress and grips of the case (the materials' pointwise parts).
void describeMaterials(const CaseParams& p, Materials& mat);
/// One strength per rod element, normal(mean, cv), seeded: drawn rod by rod along each rod from its first
/// slice (a seed's realisation does not depend on how the model numbers its rod elements); an element of the
/// reduced far field spanning n slices takes the n draws of the elements it stands for and the weakest of
/// them. Infinite when rods are unbreakable.
std::vector<double> drawRodStrengths(const Model& m, const CaseParams& p);
/// The element matrices of each class of rod element (all rods of a ply share one orientation, so one class
/// per ply and, in a reduced far field, per span): K, consistent and lumped M, the local force and stress
/// operators and the stress-change bound; and the largest element frequency.
void buildElementClasses(const Model& m, Materials& mat);
/// K and M assembled from the classes' matrices; the rod elements cut by the pre-crack carry no stiffness but
/// keep their mass, lumped at their nodes (as a deleted element does), so a rod end the cut isolates is not
/// massless.
void assembleOperators(const Model& m, const Materials& mat, Operators& ops);
/// E_transverse (measured by measureTransverseModulus unless the case gives it), c_d, the Rayleigh damping
/// C = a M + b K (a = zeta w_min, b = zeta / w_min, w_min = pi c_d / h_s) and the loading's velocity and ramp.
void setWaveSpeedDampingAndLoading(const CaseParams& p, const Model& m, Materials& mat);
/// The grips: u_y of the top (+) and bottom (-) rows prescribed as shape x U, shape = Grips::shape (default
/// +/-(1 - x/w_s)), with its per-DOF slope; with Grips::holdUx their u_x = 0 too (shape and slope 0, after the
/// u_y); the free DOFs.
void prescribeGrips(const Model& m, const Grips& grips, Operators& ops);
/// Node -> interface ends (CSR), for the deterministic gather of interface forces.
void indexInterfacesByNode(const Model& m, Operators& ops);
/// The slices' ranges of nodes and interfaces and the interfaces' in-slice form; throws SolverError when the
/// model is not numbered slice by slice (what the kernels rely on).
void indexSlices(const Model& m, Operators& ops);
/// The state at rest: zero displacements and velocities, every interface and rod element intact.
State stateAtRest(const Model& m, const Operators& ops);
/// Worker threads of the force loops: the case key `threads`, or one per 30k DOF up to all cores.
void setThreadCount(const CaseParams& p, int numDofs);

/// Measure E_transverse (modulus in the loading direction y) with the model itself: a static uniaxial
/// stretch of an uncracked block of the same microstructure, rods plus elastic interfaces, top and bottom
/// rows displaced by +/- delta/2, everything else free (one node fixed in x and z against rigid motion).
double measureTransverseModulus(const CaseParams& p, double* blockStrain = nullptr);

}  // namespace enamel
