#pragma once
// 3D Euler-Bernoulli beam element for the enamel rods (docs/model.md), as pure functions:
// section properties, local frame, local/global stiffness and mass, end forces, the brittle stress
// check and the element eigenfrequencies that set the stable time step.
// GCC 12 emits a known false-positive -Wmaybe-uninitialized from Eigen's self-adjoint eigensolver
// (SelfadjointMatrixVector.h, used by eigenfrequencies); it must be silenced where Eigen is parsed.
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif
#include <Eigen/Dense>
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic pop
#endif

#include <string>

#include "base/choices.hpp"

namespace enamel::beam {

using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;
using Vec12 = Eigen::Matrix<double, 12, 1>;
using Mat12 = Eigen::Matrix<double, 12, 12>;

// DOF order everywhere: node a (ux uy uz rx ry rz), then node b (same). Local axis x' from a to b.
struct Section {
  double E, G, rho;  // Young's modulus, shear modulus, density
  double A;          // area
  double Iy, Iz;     // second moments of area about local y', z'
  double Ip;         // polar moment Iy+Iz (torsional rotary inertia)
  double J;          // torsion constant (stiffness GJ/L)
  double c;          // extreme-fibre distance for the stress check
};

// Space-filling regular hexagon of across-flats width d:
//   A = sqrt(3)/2 d^2, Iy = Iz = 5 sqrt(3)/144 d^4, Ip = Iy + Iz, J = 0.11505 d^4, c = d/2, G = E/(2(1+nu)).
// J is computed (see beam.cpp), not taken from a table.
Section hexagonalSection(double d, double E, double nu, double rho);
// Circle of diameter d: A = pi d^2/4, Iy = Iz = pi d^4/64, Ip = J = pi d^4/32, c = d/2.
Section circularSection(double d, double E, double nu, double rho);

// Rows of the returned matrix are the local unit axes e1 (a->b), e2, e3, so v_local = R * v_global.
// e3 = normalize(zhat - (zhat.e1) e1) (= e1 x (zhat x e1)), e2 = e3 x e1: a beam in the xy-plane has
// e3 = +z. A beam parallel to z gets e2 = +x, e3 = e1 x e2.
Mat3 localFrame(const Vec3& xa, const Vec3& xb);

// Standard 3D Euler-Bernoulli stiffness in the local frame (axial EA/L, torsion GJ/L, bending in x'y'
// with Iz and in x'z' with Iy; no shear deformation).
Mat12 localStiffness(const Section& s, double L);
// Consistent translational mass (linear shape functions for axial, cubic Hermite for bending) plus
// torsional rotary inertia rho Ip L/6 [2 1; 1 2]; no bending rotary inertia. Positive definite.
Mat12 localConsistentMass(const Section& s, double L);
// Diagonal lumped mass: translations rho A L/2 per node; rotations rotaryScale * rho L/2 * (Ip, Iy, Iz).
Vec12 lumpedMassDiagonal(const Section& s, double L, double rotaryScale = 1.0);

// T^T M T with T = blockdiag(R, R, R, R) (R from localFrame): local -> global for K or M.
Mat12 rotateToGlobal(const Mat12& Mlocal, const Mat3& R);
Mat12 globalStiffness(const Section& s, const Vec3& xa, const Vec3& xb);
Mat12 globalConsistentMass(const Section& s, const Vec3& xa, const Vec3& xb);

// f_local = K_local * T * u_global: the nodal forces/moments (local axes) that must be APPLIED to the
// element's nodes to hold the displacement u_global. The element exerts -f_local on its nodes, so the
// internal-force contribution to the global residual is +T^T f_local (M a + K u = f_ext).
Vec12 localEndForces(const Section& s, double L, const Mat3& R, const Vec12& uGlobal);

// Brittle check (docs/model.md): max over both ends of
//   sigma = N/A + sqrt((My c/Iy)^2 + (Mz c/Iz)^2),  N = f_local[6] = -f_local[0] (tension positive),
// end moments (My, Mz) = f_local[4,5] at node a and f_local[10,11] at node b.
double maxTensileStress(const Section& s, const Vec12& fLocal);

// The local end forces the stress check reads (the rest never enter it): axial force at end B and the two
// bending moments at each end, fLocal[kStressRows[r]]; so the check needs 5 rows of K_local T, not 12.
inline constexpr int kStressRows[5] = {4, 5, 6, 10, 11};
using Vec5 = Eigen::Matrix<double, 5, 1>;
// maxTensileStress of the end forces fLocal[kStressRows] (the code the solver runs; the Vec12 form calls it).
double maxTensileStressOfRows(const Section& s, const Vec5& f);

// The rows kStressRows of K_local T for one element orientation: u_e (12 global DOFs) -> the Vec5 above.
using StressOperator = Eigen::Matrix<double, 5, 12, Eigen::RowMajor>;
// How fast the stress check's stress can change with the element's displacements: for any u, u',
//   |maxTensileStressOfRows(S u') - maxTensileStressOfRows(S u)| <= L max_i |u'_i - u_i|,
//   L = ||S_N||_1 / A + max over the ends (||S_My||_1 c/Iy + ||S_Mz||_1 c/Iz)
// (row norms ||.||_1 of S; the max of two ends and sqrt(a^2 + b^2) change by at most the largest change of
// their arguments and |da| + |db|). The deletion check uses it to skip elements that cannot reach their
// strength before the displacements have moved far enough (kernels.hpp, StressCheckSchedule).
double stressChangeBound(const Section& s, const StressOperator& S);

// Alternative rod stress definitions (case key rod_stress), for the paper's undefined "maximum rod stress
// sigma_r,max"; the default axial_bending is maxTensileStressOfRows above. All are tension positive and
// scale linearly with the displacements (positively homogeneous), as the static start's U_c needs. The kinds are
// the case key's enum RodStress (choices.hpp).

// axial: sigma = N/A (N = f[2] = f_local[6], the same at both ends); needs only the kStressRows rows.
double axialStressOfRows(const Section& s, const Vec5& f);

// The torque the principal stress reads: T = f_local[kTorsionRow] (end b; = -f_local[3], constant along the
// element). Only rod_stress = principal evaluates this 6th row, so the default's 5 rows and cost are unchanged.
inline constexpr int kTorsionRow = 9;
// principal: largest principal stress at the outer fibre of the most stressed end,
//   sigma_1 = sigma/2 + sqrt((sigma/2)^2 + tau^2),  sigma = maxTensileStressOfRows(f),  tau = |T| c/J,
// with tau from torsion only (no transverse shear) and c/J the circle's formula (exact for the circle, the
// hexagon's c = d/2 and computed J otherwise). sigma_1 increases with sigma, and tau is the same at both ends,
// so the max over the ends is sigma_1 of the max sigma. Equals sigma when T = 0 (up to round-off).
double principalStressOfRows(const Section& s, const Vec5& f, double torque);

// The stress of `kind` from the kStressRows end forces and the torque (what the solver's alternative loop runs;
// the default loop calls maxTensileStressOfRows directly).
double rodStressOfRows(RodStress kind, const Section& s, const Vec5& f, double torque);
// The same from all 12 local end forces (tests).
double rodStress(RodStress kind, const Section& s, const Vec12& fLocal);

// Free-free element eigenfrequencies omega (rad per unit time) of K phi = omega^2 M phi, ascending;
// the six rigid-body zeros come out as round-off and are clamped at 0. M must be positive definite
// (throws std::invalid_argument otherwise, e.g. lumped mass with rotaryScale = 0).
Eigen::VectorXd eigenfrequencies(const Mat12& K, const Mat12& M);

enum class MassKind { Consistent, Lumped };
// Largest element frequency (governs the stable time step), rotaryScale used for Lumped only.
double maxFrequency(const Section& s, double L, MassKind kind, double rotaryScale = 1.0);

// Closed forms for the consistent-mass element (verified against eigenfrequencies in test_beam.cpp):
//   axial   omega_max = sqrt(12 E/rho) / L                    (linear bar, free-free)
//   bending omega_max = sqrt(8400 E I / (rho A L^4))          (cubic Hermite, free-free; the other
//                                                              flexible bending mode is 720)
// Hexagon, d = E = rho = 1, L = 0.3: bending ~268.4, axial ~11.55.
double closedFormAxialOmegaMax(const Section& s, double L);
double closedFormBendingOmegaMax(const Section& s, double L, double I);

}  // namespace enamel::beam
