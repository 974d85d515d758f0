// Tests for the 3D Euler-Bernoulli beam element (solver/lib/laws/beam.hpp): physical invariants with stated
// tolerances, no mesh needed beyond a small dense cantilever assembled here.
#include "laws/beam.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <stdexcept>
#include <string>
#include <vector>

using namespace enamel::beam;
using enamel::RodStress;  // the case key rod_stress (choices.hpp)

namespace {

// Round-off on O(1)-conditioned 12x12 products: a few hundred ulps.
constexpr double kTolStiffness = 1e-10;
// Symmetry is exact up to the order of floating-point summation in T^T M T.
constexpr double kTolSymmetry = 1e-12;
// Mass sums are short sums of O(1) terms.
constexpr double kTolMassSum = 1e-12;
// Cubic Hermite elements reproduce the cantilever (cubic) exactly; the residual is the solve's round-off
// with condition number ~ (L/h)^2 (L/r)^2 for N = 16 elements.
constexpr double kTolCantilever = 1e-9;
// Generalised eigenvalues of a 12x12 pencil: Cholesky + QR round-off times the spread 268/7 of frequencies.
constexpr double kTolFrequency = 1e-8;
// Stress formulas are a handful of flops.
constexpr double kTolStress = 1e-12;

// A section with all distinct properties, so that a swapped Iy/Iz, J/Ip or E/G shows up.
Section testSection() {
  Section s;
  s.E = 2.0;
  s.G = 0.7;
  s.rho = 1.3;
  s.A = 0.9;
  s.Iy = 0.05;
  s.Iz = 0.08;
  s.Ip = s.Iy + s.Iz;
  s.J = 0.11;
  s.c = 0.5;
  return s;
}

// An arbitrarily oriented beam (not in any coordinate plane) and one in the xy-plane like our rods.
const Vec3 kXa(0.3, -0.2, 0.5);
const Vec3 kXb(1.1, 0.4, -0.1);
const Vec3 kXaPlane(0.2, 0.1, 0.0);
const Vec3 kXbPlane(0.2 + 0.3 * std::cos(0.5), 0.1 + 0.3 * std::sin(0.5), 0.0);

Mat12 blockRot(const Mat3& R) {
  Mat12 T = Mat12::Zero();
  for (int k = 0; k < 4; ++k) T.block<3, 3>(3 * k, 3 * k) = R;
  return T;
}

double relErr(double a, double b) { return std::abs(a - b) / std::abs(b); }

}  // namespace

// Section formulas: hexagon of across-flats d (docs/model.md) and circle.
TEST(Beam, SectionProperties) {
  const double d = 1.7;
  const Section h = hexagonalSection(d, 1.0, 0.3, 1.0);
  EXPECT_NEAR(h.A, std::sqrt(3.0) / 2.0 * d * d, 1e-14);
  EXPECT_NEAR(h.Iy, 5.0 * std::sqrt(3.0) / 144.0 * std::pow(d, 4), 1e-14);
  EXPECT_DOUBLE_EQ(h.Iy, h.Iz);
  EXPECT_DOUBLE_EQ(h.Ip, h.Iy + h.Iz);
  EXPECT_NEAR(h.G, 1.0 / 2.6, 1e-15);
  EXPECT_DOUBLE_EQ(h.c, d / 2.0);
  // Saint-Venant J of the hexagon: our computed 0.11505 d^4 against Roark's ~0.1154 d^4 (0.5%: table
  // rounding), and strictly below the polar moment (equality only for a circle).
  EXPECT_NEAR(h.J / std::pow(d, 4), 0.1154, 0.005 * 0.1154);
  EXPECT_LT(h.J, h.Ip);
  const Section c = circularSection(d, 1.0, 0.3, 1.0);
  EXPECT_NEAR(c.A, M_PI * d * d / 4.0, 1e-14);
  EXPECT_NEAR(c.Iz, M_PI * std::pow(d, 4) / 64.0, 1e-14);
  EXPECT_DOUBLE_EQ(c.J, c.Ip);
}

// Local frame: orthonormal, right-handed, e1 along the beam, e3 = +z for beams in the xy-plane, e2 = +x
// for beams along z.
TEST(Beam, LocalFrame) {
  constexpr double tol = 1e-14;  // a few normalisations and cross products
  for (const auto& [xa, xb] : {std::pair{kXa, kXb}, std::pair{kXaPlane, kXbPlane}}) {
    const Mat3 R = localFrame(xa, xb);
    EXPECT_LT((R * R.transpose() - Mat3::Identity()).norm(), tol);
    EXPECT_NEAR(R.determinant(), 1.0, tol);
    EXPECT_LT((R * (xb - xa) - Vec3((xb - xa).norm(), 0, 0)).norm(), tol);
  }
  EXPECT_LT((localFrame(kXaPlane, kXbPlane).row(2).transpose() - Vec3::UnitZ()).norm(), tol);
  for (double sz : {1.0, -1.0}) {
    const Mat3 R = localFrame(Vec3(1, 2, 3), Vec3(1, 2, 3 + sz));
    EXPECT_LT((R.row(1).transpose() - Vec3::UnitX()).norm(), tol);
    EXPECT_NEAR(R.determinant(), 1.0, tol);
  }
}

// Axial EA/L, bending 12EI/L^3 in both planes (Iz for y', Iy for z'), torsion GJ/L: in the local matrix
// and, for an arbitrarily oriented beam, via K_global applied to the rotated local displacement.
TEST(Beam, StiffnessAxialBendingTorsion) {
  const Section s = testSection();
  const double L = (kXb - kXa).norm();
  const Mat12 Kl = localStiffness(s, L);
  const Mat12 Kg = globalStiffness(s, kXa, kXb);
  const Mat12 T = blockRot(localFrame(kXa, kXb));
  struct Case { int dof; double expected; const char* what; };
  const Case cases[] = {
      {6, s.E * s.A / L, "axial EA/L"},
      {7, 12 * s.E * s.Iz / (L * L * L), "bending y' 12 E Iz/L^3"},
      {8, 12 * s.E * s.Iy / (L * L * L), "bending z' 12 E Iy/L^3"},
      {9, s.G * s.J / L, "torsion GJ/L"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.what);
    EXPECT_LT(relErr(Kl(c.dof, c.dof), c.expected), kTolStiffness);
    // Unit local displacement at node b, rotated to global; the force held at b, back in local axes.
    Vec12 uLocal = Vec12::Zero();
    uLocal[c.dof] = 1.0;
    const Vec12 fLocal = T * (Kg * (T.transpose() * uLocal));
    EXPECT_LT(relErr(fLocal[c.dof], c.expected), kTolStiffness);
    EXPECT_LT((fLocal - Kl * uLocal).norm(), kTolStiffness * Kl.norm());
    // localEndForces is the same map.
    EXPECT_LT((localEndForces(s, L, localFrame(kXa, kXb), T.transpose() * uLocal) - fLocal).norm(),
              kTolStiffness * Kl.norm());
  }
  // Equilibrium of a tip-loaded clamped-free element: the fixed end reacts -P and the moment P L.
  const double Lc = 0.3;
  const Mat12 K = localStiffness(s, Lc);
  Vec12 u = Vec12::Zero();
  u.tail<6>() = K.bottomRightCorner<6, 6>().ldlt().solve(Eigen::Matrix<double, 6, 1>::UnitY());
  const Vec12 f = K * u;
  EXPECT_NEAR(u[7], Lc * Lc * Lc / (3 * s.E * s.Iz), kTolStiffness);
  EXPECT_NEAR(f[1], -1.0, kTolStiffness);
  EXPECT_NEAR(f[5], -Lc, kTolStiffness);
}

// Six rigid-body modes (3 translations, 3 small rotations u = w x (x - p), theta = w) of an arbitrarily
// oriented beam produce no nodal force.
TEST(Beam, RigidBodyModesGiveZeroForce) {
  const Section s = testSection();
  const Mat12 K = globalStiffness(s, kXa, kXb);
  const double scale = K.cwiseAbs().maxCoeff();
  const Vec3 p(-0.4, 0.9, 0.25);
  for (int k = 0; k < 6; ++k) {
    Vec12 u = Vec12::Zero();
    if (k < 3) {
      u.segment<3>(0) = u.segment<3>(6) = Vec3::Unit(k);
    } else {
      const Vec3 w = Vec3::Unit(k - 3);
      u.segment<3>(0) = w.cross(kXa - p);
      u.segment<3>(3) = w;
      u.segment<3>(6) = w.cross(kXb - p);
      u.segment<3>(9) = w;
    }
    EXPECT_LT((K * u).cwiseAbs().maxCoeff(), kTolStiffness * scale * u.norm()) << "mode " << k;
  }
}

// Total translational mass in each global direction (1^T M_tt 1) is rho A L, for consistent and lumped
// mass; the torsional rotary inertia of a uniform spin is rho Ip L.
TEST(Beam, MassSums) {
  const Section s = testSection();
  const double L = (kXb - kXa).norm();
  const double mass = s.rho * s.A * L;
  const Mat12 Mg = globalConsistentMass(s, kXa, kXb);
  const Vec12 ml = lumpedMassDiagonal(s, L, 0.7);
  for (int dir = 0; dir < 3; ++dir) {
    Vec12 one = Vec12::Zero();
    one[dir] = one[6 + dir] = 1.0;
    EXPECT_LT(relErr(one.dot(Mg * one), mass), kTolMassSum) << "consistent, direction " << dir;
    EXPECT_LT(relErr(ml[dir] + ml[6 + dir], mass), kTolMassSum) << "lumped, direction " << dir;
  }
  Vec12 spin = Vec12::Zero();
  spin[3] = spin[9] = 1.0;  // local uniform twist
  EXPECT_LT(relErr(spin.dot(localConsistentMass(s, L) * spin), s.rho * s.Ip * L), kTolMassSum);
  EXPECT_LT(relErr(ml[3] + ml[9], 0.7 * s.rho * s.Ip * L), kTolMassSum);
  EXPECT_LT(relErr(ml[5] + ml[11], 0.7 * s.rho * s.Iz * L), kTolMassSum);
}

// Cantilever of N = 1, 4, 16 elements along an arbitrary direction, clamped at node 0, tip load P along
// e2 and along e3: tip deflection P L^3/(3 E I) and tip rotation P L^2/(2 E I), exact for Hermite elements.
TEST(Beam, CantileverTipDeflection) {
  const Section s = testSection();
  const Vec3 x0 = kXa, dir = (kXb - kXa).normalized();
  const double Ltot = 2.4, P = 0.01;
  const Mat3 R = localFrame(x0, x0 + dir);
  for (int N : {1, 4, 16}) {
    const int n = 6 * (N + 1);
    Eigen::MatrixXd K = Eigen::MatrixXd::Zero(n, n);
    for (int e = 0; e < N; ++e) {
      const Vec3 xa = x0 + dir * (Ltot * e / N), xb = x0 + dir * (Ltot * (e + 1) / N);
      K.block<12, 12>(6 * e, 6 * e) += globalStiffness(s, xa, xb);
    }
    const Eigen::MatrixXd Kff = K.bottomRightCorner(n - 6, n - 6);  // clamp node 0
    const Eigen::LDLT<Eigen::MatrixXd> ldlt(Kff);
    for (int axis : {1, 2}) {  // load along e2 (bends with Iz) and e3 (bends with Iy)
      SCOPED_TRACE("N = " + std::to_string(N) + ", axis e" + std::to_string(axis + 1));
      const double I = (axis == 1) ? s.Iz : s.Iy;
      Eigen::VectorXd f = Eigen::VectorXd::Zero(n - 6);
      f.tail<6>().head<3>() = P * R.row(axis).transpose();
      const Eigen::VectorXd u = ldlt.solve(f);
      const Vec3 tipU = R * u.tail<6>().head<3>();
      const Vec3 tipTheta = R * u.tail<6>().tail<3>();
      EXPECT_LT(relErr(tipU[axis], P * std::pow(Ltot, 3) / (3 * s.E * I)), kTolCantilever);
      // theta_z = +v', theta_y = -w'.
      const double theta = (axis == 1) ? tipTheta[2] : -tipTheta[1];
      EXPECT_LT(relErr(theta, P * Ltot * Ltot / (2 * s.E * I)), kTolCantilever);
    }
  }
}

// Hexagonal rod, L = 0.3 d (paper's coarse h_e): the highest consistent-mass frequency is a bending mode
// and equals sqrt(8400 E I/(rho A L^4)) ~ 268; the axial mode equals sqrt(12 E/rho)/L ~ 11.5.
TEST(Beam, ConsistentMassFrequenciesHexagon) {
  const Section s = hexagonalSection(1.0, 1.0, 0.3, 1.0);
  const double L = 0.3;
  const Mat12 K = localStiffness(s, L), M = localConsistentMass(s, L);
  const Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> eig(K, M);
  const Eigen::VectorXd omega2 = eig.eigenvalues();
  const Eigen::MatrixXd& V = eig.eigenvectors();
  const Eigen::VectorXd omega = eigenfrequencies(K, M);
  const double wBend = closedFormBendingOmegaMax(s, L, s.Iz);
  const double wAxial = closedFormAxialOmegaMax(s, L);

  // Six rigid-body zeros (clamped round-off) below 1e-6 of the top frequency.
  for (int i = 0; i < 6; ++i) EXPECT_LT(omega[i], 1e-6 * omega[11]) << "rigid mode " << i;
  // Top mode: bending (transverse components dominate the axial ones) at the closed form.
  const auto axialNorm = [&](int i) { return std::hypot(V(0, i), V(6, i)); };
  const auto transverseNorm = [&](int i) {
    return Eigen::Vector4d(V(1, i), V(2, i), V(7, i), V(8, i)).norm();
  };
  EXPECT_GT(transverseNorm(11), 10.0 * axialNorm(11));
  EXPECT_LT(relErr(std::sqrt(omega2[11]), wBend), kTolFrequency);
  EXPECT_LT(relErr(omega[11], wBend), kTolFrequency);
  EXPECT_LT(relErr(maxFrequency(s, L, MassKind::Consistent), wBend), kTolFrequency);
  // Axial mode: the eigenvector with the largest axial share.
  int iAxial = 6;
  for (int i = 6; i < 12; ++i)
    if (axialNorm(i) / V.col(i).norm() > axialNorm(iAxial) / V.col(iAxial).norm()) iAxial = i;
  EXPECT_GT(axialNorm(iAxial), 0.99 * V.col(iAxial).norm());
  EXPECT_LT(relErr(omega[iAxial], wAxial), kTolFrequency);
  // The other flexible bending mode sits at sqrt(720 E I/(rho A L^4)) (twice: Iy = Iz).
  const double wBendSym = std::sqrt(720.0 * s.E * s.Iz / (s.rho * s.A * std::pow(L, 4)));
  int nSym = 0;
  for (int i = 6; i < 12; ++i) nSym += relErr(omega[i], wBendSym) < kTolFrequency;
  EXPECT_EQ(nSym, 2);
  // The element frequencies behind docs/solver.md (omega_max ~270 against ~11.6 axial at h_e = 0.3 d).
  EXPECT_NEAR(wBend, 268.4, 0.1);
  EXPECT_NEAR(wAxial, 11.55, 0.01);
}

// Lumped mass (rotaryScale = 1): the axial mode (u_a = -u_b) is sqrt(4 E/rho)/L exactly, and so are the
// two pure-rotation bending modes (theta_a = -theta_b, no translation): (2 EI/L)/(rho I L/2) = 4 E/(rho L^2).
// Rotary-inertia scaling lowers the top frequency, which sits far below the consistent one; a massless
// rotation (rotaryScale = 0) is refused.
TEST(Beam, LumpedMassFrequencies) {
  const Section s = hexagonalSection(1.0, 1.0, 0.3, 1.0);
  const double L = 0.3;
  const Mat12 K = localStiffness(s, L);
  const Eigen::VectorXd omega = eigenfrequencies(K, Mat12(lumpedMassDiagonal(s, L).asDiagonal()));
  const double wAxial = 2.0 * std::sqrt(s.E / s.rho) / L;
  int nAt2overL = 0;
  for (int i = 6; i < 12; ++i) nAt2overL += relErr(omega[i], wAxial) < kTolFrequency;
  EXPECT_EQ(nAt2overL, 3);
  const double w1 = maxFrequency(s, L, MassKind::Lumped, 1.0);
  const double w10 = maxFrequency(s, L, MassKind::Lumped, 10.0);
  EXPECT_LT(w10, w1);
  // docs/solver.md: lumped mass allows a step "tens of times larger" than the consistent one.
  EXPECT_GT(maxFrequency(s, L, MassKind::Consistent) / w1, 10.0);
  EXPECT_THROW(maxFrequency(s, L, MassKind::Lumped, 0.0), std::invalid_argument);
}

// Brittle check: pure tension N/A, pure bending M c/I (either plane), biaxial bending combines as
// sqrt, tension plus bending adds; also through localEndForces of a stretched / bent element.
TEST(Beam, MaxTensileStress) {
  const Section s = testSection();
  const double N = 0.37, M = 0.21, M2 = 0.13;
  Vec12 tension = Vec12::Zero();
  tension[0] = -N;
  tension[6] = N;
  EXPECT_LT(relErr(maxTensileStress(s, tension), N / s.A), kTolStress);
  EXPECT_LT(relErr(maxTensileStress(s, -tension), -N / s.A), kTolStress);  // compression: negative
  Vec12 bendZ = Vec12::Zero();  // constant moment about z'
  bendZ[5] = -M;
  bendZ[11] = M;
  EXPECT_LT(relErr(maxTensileStress(s, bendZ), M * s.c / s.Iz), kTolStress);
  Vec12 bendY = Vec12::Zero();  // constant moment about y'
  bendY[4] = -M2;
  bendY[10] = M2;
  EXPECT_LT(relErr(maxTensileStress(s, bendY), M2 * s.c / s.Iy), kTolStress);
  EXPECT_LT(relErr(maxTensileStress(s, bendY + bendZ), std::hypot(M * s.c / s.Iz, M2 * s.c / s.Iy)),
            kTolStress);
  EXPECT_LT(relErr(maxTensileStress(s, tension + bendZ), N / s.A + M * s.c / s.Iz), kTolStress);

  // Through the element: stretch by delta gives E delta/L; end rotations -/+alpha about z' give a
  // constant curvature 2 alpha/L, so sigma = E c 2 alpha/L.
  const double L = (kXb - kXa).norm(), delta = 1e-3, alpha = 2e-3;
  const Mat3 R = localFrame(kXa, kXb);
  const Mat12 T = blockRot(R);
  Vec12 uLocal = Vec12::Zero();
  uLocal[6] = delta;
  EXPECT_LT(relErr(maxTensileStress(s, localEndForces(s, L, R, T.transpose() * uLocal)),
                   s.E * delta / L), kTolStress * 1e3);  // through a 12x12 product: looser
  uLocal.setZero();
  uLocal[5] = -alpha;
  uLocal[11] = alpha;
  EXPECT_LT(relErr(maxTensileStress(s, localEndForces(s, L, R, T.transpose() * uLocal)),
                   s.E * s.c * 2 * alpha / L), kTolStress * 1e3);
}

// stressChangeBound: for random pairs of displacements, the stress check's stress changes by at most
// L max_i |du_i| (what lets the deletion check skip elements), and the bound is not vacuous: the displacement
// change that follows the signs of the dominant rows reaches at least a quarter of it.
TEST(Beam, StressChangeBoundHoldsAndIsTight) {
  const Section s = testSection();
  const double L = (kXb - kXa).norm();
  const Mat3 R = localFrame(kXa, kXb);
  const Mat12 op = localStiffness(s, L) * blockRot(R);
  StressOperator S;
  for (int r = 0; r < 5; ++r) S.row(r) = op.row(kStressRows[r]);
  const double bound = stressChangeBound(s, S);
  ASSERT_GT(bound, 0.0);
  std::srand(3);
  auto random12 = [] {
    Vec12 x;
    for (int i = 0; i < 12; ++i) x[i] = std::rand() / double(RAND_MAX) - 0.5;
    return x;
  };
  double worstShare = 0;
  for (int trial = 0; trial < 2000; ++trial) {
    const Vec12 u = 1e-3 * random12(), du = std::pow(10.0, -1 - trial % 5) * random12();
    const double change = std::abs(maxTensileStressOfRows(s, S * (u + du)) - maxTensileStressOfRows(s, S * u));
    const double allowed = bound * du.cwiseAbs().maxCoeff();
    ASSERT_LE(change, allowed * (1 + 1e-12)) << "trial " << trial;
    worstShare = std::max(worstShare, change / allowed);
  }
  // du = h sign(S_N + S_My(end A)) moves N and My at end A by their row norms together
  Vec12 du;
  for (int i = 0; i < 12; ++i) du[i] = (S(2, i) / s.A + S(0, i) * s.c / s.Iy >= 0 ? 1e-4 : -1e-4);
  const double change = maxTensileStressOfRows(s, S * du) - maxTensileStressOfRows(s, Vec5(Vec5::Zero()));
  EXPECT_GT(change, 0.25 * bound * 1e-4);
  EXPECT_GT(worstShare, 0.05);
}

// K and M symmetric (local and global); M positive definite; K positive semi-definite with exactly
// six zero eigenvalues.
TEST(Beam, SymmetryAndDefiniteness) {
  const Section s = testSection();
  const double L = (kXb - kXa).norm();
  const Mat12 mats[] = {localStiffness(s, L), localConsistentMass(s, L), globalStiffness(s, kXa, kXb),
                        globalConsistentMass(s, kXa, kXb)};
  for (const Mat12& A : mats)
    EXPECT_LT((A - A.transpose()).cwiseAbs().maxCoeff(), kTolSymmetry * A.cwiseAbs().maxCoeff());
  for (const Mat12& M : {mats[1], mats[3]}) {
    EXPECT_EQ(Eigen::LLT<Mat12>(M).info(), Eigen::Success);
    const Eigen::SelfAdjointEigenSolver<Mat12> eig(M);
    EXPECT_GT(eig.eigenvalues().minCoeff(), 1e-6 * eig.eigenvalues().maxCoeff());
  }
  const Eigen::SelfAdjointEigenSolver<Mat12> eigK(mats[2]);
  const double kmax = eigK.eigenvalues().maxCoeff();
  int nZero = 0;
  for (int i = 0; i < 12; ++i) {
    EXPECT_GT(eigK.eigenvalues()[i], -kTolStiffness * kmax);
    nZero += eigK.eigenvalues()[i] < kTolStiffness * kmax;
  }
  EXPECT_EQ(nZero, 6);
}

// Case key rod_stress: the alternatives to the default N/A + bending, on hand-made end forces and through
// the element (torsion by a relative twist phi: T = G J phi/L).
TEST(Beam, RodStressDefinitions) {
  const Section s = testSection();
  const double N = 0.37, M = 0.21, Tq = 0.17;
  Vec12 f = Vec12::Zero();
  f[0] = -N, f[6] = N;      // tension N
  f[5] = -M, f[11] = M;     // constant moment about z'
  f[3] = -Tq, f[9] = Tq;    // torque
  const double sigma = N / s.A + M * s.c / s.Iz, tau = Tq * s.c / s.J;
  EXPECT_EQ(rodStress(RodStress::axial_bending, s, f), maxTensileStress(s, f));  // the default is the same code
  EXPECT_LT(relErr(rodStress(RodStress::axial, s, f), N / s.A), kTolStress);
  EXPECT_LT(relErr(rodStress(RodStress::axial, s, -f), -N / s.A), kTolStress);  // compression: negative
  const double sigma1 = sigma / 2 + std::sqrt(sigma * sigma / 4 + tau * tau);
  EXPECT_LT(relErr(rodStress(RodStress::principal, s, f), sigma1), kTolStress);
  // The torque's sign does not matter; without torque principal = axial_bending; with torque it is larger.
  Vec12 g = f;
  g[3] = Tq, g[9] = -Tq;
  EXPECT_EQ(rodStress(RodStress::principal, s, g), rodStress(RodStress::principal, s, f));
  Vec12 noTorque = f;
  noTorque[3] = noTorque[9] = 0;
  EXPECT_LT(relErr(rodStress(RodStress::principal, s, noTorque), maxTensileStress(s, noTorque)), kTolStress);
  EXPECT_GT(rodStress(RodStress::principal, s, f), maxTensileStress(s, f));
  // Pure torsion: sigma_1 = tau (axial: 0).
  Vec12 torsion = Vec12::Zero();
  torsion[3] = -Tq, torsion[9] = Tq;
  EXPECT_LT(relErr(rodStress(RodStress::principal, s, torsion), tau), kTolStress);
  EXPECT_EQ(rodStress(RodStress::axial, s, torsion), 0.0);
  // Positively homogeneous (the static start scales U_c by the worst ratio): stress(a f) = a stress(f).
  for (RodStress kind : {RodStress::axial_bending, RodStress::axial, RodStress::principal})
    EXPECT_LT(relErr(rodStress(kind, s, 2.5 * f), 2.5 * rodStress(kind, s, f)), kTolStress);
  // The rows the solver reads: kStressRows and kTorsionRow of the same end forces.
  Vec5 rows;
  for (int r = 0; r < 5; ++r) rows[r] = f[kStressRows[r]];
  EXPECT_EQ(principalStressOfRows(s, rows, f[kTorsionRow]), rodStress(RodStress::principal, s, f));
  EXPECT_EQ(axialStressOfRows(s, rows), rodStress(RodStress::axial, s, f));

  // Through the element: a relative twist phi about the axis gives T = G J phi/L, tau = G c phi/L.
  const double L = (kXb - kXa).norm(), phi = 3e-3;
  const Mat3 R = localFrame(kXa, kXb);
  Vec12 uLocal = Vec12::Zero();
  uLocal[9] = phi;
  const Vec12 fl = localEndForces(s, L, R, blockRot(R).transpose() * uLocal);
  EXPECT_LT(relErr(rodStress(RodStress::principal, s, fl), s.G * s.c * phi / L), kTolStress * 1e3);
  EXPECT_LT(std::abs(rodStress(RodStress::axial_bending, s, fl)), 1e-12);
}

