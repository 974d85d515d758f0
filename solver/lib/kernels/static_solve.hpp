#pragma once
// Static elastic solutions: the solve with prescribed displacements, the elastic stiffness (rods and elastic
// interfaces), and the first-damage displacement U_c of a static field (the static elastic start, the
// transverse modulus, the J and compliance checks). docs/solver.md.
#include <cstdint>
#include <vector>

#include "data/state.hpp"

namespace enamel {

/// The BLAS's own thread count, where the BLAS linked at run time has one (OpenBLAS's pthread build, Debian's
/// default, starts one thread per core whatever OpenMP is told): CHOLMOD's factorizations and solves use it.
/// blasThreadCount is 0 where the BLAS has none.
void setBlasThreadCount(int n);
int blasThreadCount();

/// Static solution of K u = 0 with u prescribed (= values) at `dofs` (CHOLMOD on the free partition). Where
/// the free partition is only semi-definite (a mechanism: a part free to move without straining anything),
/// the mechanism stays where it is and `mechanism`, if given, is set. The BLAS runs at one thread for it, so that
/// the solution does not depend on the thread count: OpenBLAS's threaded kernels add in another order on some
/// CPUs (on an Intel Xeon with AVX-512 the transverse modulus differed in its last ~10 ulps between
/// one and two threads, and with it every later number of a run).
VecX solveStaticPrescribed(const SpMat& K, const std::vector<int>& dofs, const std::vector<double>& values,
                           bool* mechanism = nullptr);

/// K of the intact rod elements (beamBroken: those deleted are left out; null: all) plus every interface's
/// elastic stiffness.
SpMat assembleElasticStiffness(const Model& m, const std::vector<beam::Mat12>& beamKPerClass,
                               const std::vector<std::uint8_t>* beamBroken, const cohesive::Law& law);

/// Add a 12x12 element matrix between nodes a and b into a triplet list.
void addElementTriplets(std::vector<Eigen::Triplet<double>>& trip, const beam::Mat12& Ke, int a, int b);

/// U_c of a static elastic displacement field q1 at unit applied displacement (linear: every opening and rod
/// stress scales with U): the smallest of delta0 / max_i lambda_i(q1) over the interfaces (when breakable)
/// and 1 / max_e sigma_e(q1) / sigma_ru,e over the intact rod elements (when breakable); infinite when
/// nothing opens or is stressed. limitedByRod says which set it.
double computeFirstDamageDisplacement(const Model& m, const Materials& mat, const VecX& q1,
                                      const std::vector<std::uint8_t>& beamBroken, bool interfacesBreakable, bool& limitedByRod);

/// The quasi-static state of the loading at time t, U(t) = U: every DOF moves with the grips in proportion to
/// the static field q1 at unit displacement (q = U q1, v = U'(t) q1, a = U''(t) q1), the reactions are the
/// static ones U R1, and the grips' power is R . v of the grips.
void setQuasiStaticState(const Operators& ops, const Loading& loading, const VecX& q1, const VecX& reaction1,
                         double U, double t, State& s);

}  // namespace enamel
