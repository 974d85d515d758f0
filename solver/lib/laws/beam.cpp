#include "laws/beam.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace enamel::beam {

namespace {

constexpr double kPi = 3.14159265358979323846;

// Local DOF indices (node a; node b adds 6).
enum : int { UX = 0, UY = 1, UZ = 2, RX = 3, RY = 4, RZ = 5 };

// Scatter a 2x2 bar block k [1 -1; -1 1]-type matrix [[p, q], [q, p]] onto DOF i of both nodes.
void addBarBlock(Mat12& M, int i, double p, double q) {
  M(i, i) += p;
  M(i + 6, i + 6) += p;
  M(i, i + 6) += q;
  M(i + 6, i) += q;
}

// Scatter a 4x4 planar bending block B, written for DOFs (w_a, w'_a, w_b, w'_b), onto the translation
// DOF t and rotation DOF r of both nodes. The rotation DOF equals sign * w':
//   x'y' plane: v, theta_z = +v'   (sign +1);   x'z' plane: w, theta_y = -w'   (sign -1).
void addBendingBlock(Mat12& M, const Eigen::Matrix4d& B, int t, int r, double sign) {
  const int idx[4] = {t, r, t + 6, r + 6};
  const double sgn[4] = {1.0, sign, 1.0, sign};
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) M(idx[i], idx[j]) += sgn[i] * sgn[j] * B(i, j);
}

// Hermite bending stiffness for (w_a, w'_a, w_b, w'_b):
//   K = EI/L^3 [12 6L -12 6L; 6L 4L^2 -6L 2L^2; -12 -6L 12 -6L; 6L 2L^2 -6L 4L^2]
Eigen::Matrix4d hermiteBendingStiffness(double EI, double L) {
  Eigen::Matrix4d B;
  B << 12, 6 * L, -12, 6 * L,
       6 * L, 4 * L * L, -6 * L, 2 * L * L,
       -12, -6 * L, 12, -6 * L,
       6 * L, 2 * L * L, -6 * L, 4 * L * L;
  return EI / (L * L * L) * B;
}

// Hermite consistent mass for (w_a, w'_a, w_b, w'_b):
//   M = rho A L/420 [156 22L 54 -13L; 22L 4L^2 13L -3L^2; 54 13L 156 -22L; -13L -3L^2 -22L 4L^2]
Eigen::Matrix4d hermiteBendingMass(double m, double L) {
  Eigen::Matrix4d B;
  B << 156, 22 * L, 54, -13 * L,
       22 * L, 4 * L * L, 13 * L, -3 * L * L,
       54, 13 * L, 156, -22 * L,
       -13 * L, -3 * L * L, -22 * L, 4 * L * L;
  return m / 420.0 * B;
}

// T = blockdiag(R, R, R, R): maps global nodal vectors (u, theta per node) to local.
Mat12 blockRotation(const Mat3& R) {
  Mat12 T = Mat12::Zero();
  for (int k = 0; k < 4; ++k) T.block<3, 3>(3 * k, 3 * k) = R;
  return T;
}

}  // namespace

// Regular hexagon, across flats d (side a = d/sqrt(3)):
//   A = sqrt(3)/2 d^2, Iy = Iz = 5 sqrt(3)/16 a^4 = 5 sqrt(3)/144 d^4 (same about every centroidal axis).
// Torsion constant J = 0.11505 d^4 (= 1.0355 a^4): computed from the Prandtl stress function,
// lap(phi) = -2 in the hexagon, phi = 0 on its boundary, J = 2 int(phi) dA, by P1 finite elements on
// uniform refinements (n = 64, 128 of each of the six equilateral triangles: J = 0.115034, 0.115047)
// and Richardson extrapolation in h^2 -> 0.115051. Roark's tabulated ~0.1154 d^4 agrees to 0.3%;
// J < Ip = 0.1203 d^4 as it must (equality only for the circle).
Section hexagonalSection(double d, double E, double nu, double rho) {
  const double d2 = d * d, d4 = d2 * d2;
  Section s;
  s.E = E;
  s.G = E / (2.0 * (1.0 + nu));
  s.rho = rho;
  s.A = std::sqrt(3.0) / 2.0 * d2;
  s.Iy = s.Iz = 5.0 * std::sqrt(3.0) / 144.0 * d4;
  s.Ip = s.Iy + s.Iz;
  s.J = 0.115051 * d4;
  s.c = d / 2.0;
  return s;
}

// Circle of diameter d: A = pi d^2/4, I = pi d^4/64, Ip = J = pi d^4/32, c = d/2.
Section circularSection(double d, double E, double nu, double rho) {
  const double d2 = d * d, d4 = d2 * d2;
  Section s;
  s.E = E;
  s.G = E / (2.0 * (1.0 + nu));
  s.rho = rho;
  s.A = kPi * d2 / 4.0;
  s.Iy = s.Iz = kPi * d4 / 64.0;
  s.Ip = s.J = kPi * d4 / 32.0;
  s.c = d / 2.0;
  return s;
}

// e1 = (xb - xa)/|xb - xa|;  e3 = normalize(zhat - (zhat.e1) e1);  e2 = e3 x e1  (right-handed: e1 x e2 = e3).
// Beam (nearly) parallel to z: e2 = +x, e3 = e1 x e2.
Mat3 localFrame(const Vec3& xa, const Vec3& xb) {
  const Vec3 e1 = (xb - xa).normalized();
  const Vec3 zhat = Vec3::UnitZ();
  const Vec3 zPerp = zhat - zhat.dot(e1) * e1;
  Vec3 e2, e3;
  if (zPerp.norm() > 1e-8) {  // |sin(angle to z)| > 1e-8: well-defined projection
    e3 = zPerp.normalized();
    e2 = e3.cross(e1);
  } else {
    e2 = Vec3::UnitX();
    e3 = e1.cross(e2);
  }
  Mat3 R;
  R.row(0) = e1;
  R.row(1) = e2;
  R.row(2) = e3;
  return R;
}

// Axial EA/L [1 -1; -1 1], torsion GJ/L [1 -1; -1 1], Hermite bending with E Iz (x'y') and E Iy (x'z').
Mat12 localStiffness(const Section& s, double L) {
  Mat12 K = Mat12::Zero();
  addBarBlock(K, UX, s.E * s.A / L, -s.E * s.A / L);
  addBarBlock(K, RX, s.G * s.J / L, -s.G * s.J / L);
  addBendingBlock(K, hermiteBendingStiffness(s.E * s.Iz, L), UY, RZ, +1.0);
  addBendingBlock(K, hermiteBendingStiffness(s.E * s.Iy, L), UZ, RY, -1.0);
  return K;
}

// Axial rho A L/6 [2 1; 1 2], torsion rho Ip L/6 [2 1; 1 2], Hermite translational bending mass in both
// planes (no bending rotary inertia).
Mat12 localConsistentMass(const Section& s, double L) {
  const double m = s.rho * s.A * L;
  const double mt = s.rho * s.Ip * L;
  Mat12 M = Mat12::Zero();
  addBarBlock(M, UX, m / 3.0, m / 6.0);
  addBarBlock(M, RX, mt / 3.0, mt / 6.0);
  addBendingBlock(M, hermiteBendingMass(m, L), UY, RZ, +1.0);
  addBendingBlock(M, hermiteBendingMass(m, L), UZ, RY, -1.0);
  return M;
}

// Per node: (rho A L/2) x 3 translations; rotaryScale * rho L/2 * (Ip, Iy, Iz) for (rx, ry, rz).
Vec12 lumpedMassDiagonal(const Section& s, double L, double rotaryScale) {
  const double mt = s.rho * s.A * L / 2.0;
  const double mr = rotaryScale * s.rho * L / 2.0;
  Vec12 m;
  for (int n = 0; n < 2; ++n)
    m.segment<6>(6 * n) << mt, mt, mt, mr * s.Ip, mr * s.Iy, mr * s.Iz;
  return m;
}

// M_global = T^T M_local T, T = blockdiag(R, R, R, R).
Mat12 rotateToGlobal(const Mat12& Mlocal, const Mat3& R) {
  const Mat12 T = blockRotation(R);
  return T.transpose() * Mlocal * T;
}

Mat12 globalStiffness(const Section& s, const Vec3& xa, const Vec3& xb) {
  return rotateToGlobal(localStiffness(s, (xb - xa).norm()), localFrame(xa, xb));
}

Mat12 globalConsistentMass(const Section& s, const Vec3& xa, const Vec3& xb) {
  return rotateToGlobal(localConsistentMass(s, (xb - xa).norm()), localFrame(xa, xb));
}

// f_local = K_local T u_global (forces that hold the element in the displaced state).
Vec12 localEndForces(const Section& s, double L, const Mat3& R, const Vec12& uGlobal) {
  Vec12 uLocal;
  for (int k = 0; k < 4; ++k) uLocal.segment<3>(3 * k) = R * uGlobal.segment<3>(3 * k);
  return localStiffness(s, L) * uLocal;
}

// sigma_end = N/A + sqrt((My c/Iy)^2 + (Mz c/Iz)^2), N = f_local[6] (= -f_local[0] by equilibrium),
// max over the two ends (the moment is linear along the element, so its extremes sit at the ends).
double maxTensileStressOfRows(const Section& s, const Vec5& f) {
  const double axial = f[2] / s.A;
  // sqrt(a^2 + b^2) rather than std::hypot: no overflow is possible at these magnitudes, and it is 5x cheaper
  auto norm2 = [](double a, double b) { return std::sqrt(a * a + b * b); };
  const double bendA = norm2(f[0] * s.c / s.Iy, f[1] * s.c / s.Iz);
  const double bendB = norm2(f[3] * s.c / s.Iy, f[4] * s.c / s.Iz);
  return axial + std::max(bendA, bendB);
}

// L = ||S_2||_1 / A + max(||S_0||_1 c/Iy + ||S_1||_1 c/Iz, ||S_3||_1 c/Iy + ||S_4||_1 c/Iz)
double stressChangeBound(const Section& s, const StressOperator& S) {
  auto norm1 = [&](int r) { return S.row(r).cwiseAbs().sum(); };
  const double endA = norm1(0) * s.c / s.Iy + norm1(1) * s.c / s.Iz;
  const double endB = norm1(3) * s.c / s.Iy + norm1(4) * s.c / s.Iz;
  return norm1(2) / s.A + std::max(endA, endB);
}

double maxTensileStress(const Section& s, const Vec12& fLocal) {
  Vec5 f;
  for (int r = 0; r < 5; ++r) f[r] = fLocal[kStressRows[r]];
  return maxTensileStressOfRows(s, f);
}

// sigma = N/A, N = f_local[6] (tension positive)
double axialStressOfRows(const Section& s, const Vec5& f) { return f[2] / s.A; }

// sigma_1 = sigma/2 + sqrt((sigma/2)^2 + tau^2), tau = |T| c/J
double principalStressOfRows(const Section& s, const Vec5& f, double torque) {
  const double half = 0.5 * maxTensileStressOfRows(s, f);
  const double tau = std::abs(torque) * s.c / s.J;
  return half + std::sqrt(half * half + tau * tau);
}

double rodStressOfRows(RodStress kind, const Section& s, const Vec5& f, double torque) {
  switch (kind) {
    case RodStress::axial: return axialStressOfRows(s, f);
    case RodStress::principal: return principalStressOfRows(s, f, torque);
    case RodStress::axial_bending: break;
  }
  return maxTensileStressOfRows(s, f);
}

double rodStress(RodStress kind, const Section& s, const Vec12& fLocal) {
  Vec5 f;
  for (int r = 0; r < 5; ++r) f[r] = fLocal[kStressRows[r]];
  return rodStressOfRows(kind, s, f, fLocal[kTorsionRow]);
}

// K phi = omega^2 M phi, ascending; negative round-off eigenvalues (rigid-body modes) clamped to 0.
Eigen::VectorXd eigenfrequencies(const Mat12& K, const Mat12& M) {
  if (Eigen::LLT<Mat12>(M).info() != Eigen::Success)
    throw std::invalid_argument("beam::eigenfrequencies: mass matrix is not positive definite");
  const Eigen::GeneralizedSelfAdjointEigenSolver<Mat12> eig(K, M, Eigen::EigenvaluesOnly);
  return eig.eigenvalues().cwiseMax(0.0).cwiseSqrt();
}

double maxFrequency(const Section& s, double L, MassKind kind, double rotaryScale) {
  const Mat12 K = localStiffness(s, L);  // frequencies are frame-independent: use the local frame
  const Mat12 M = (kind == MassKind::Consistent)
                      ? localConsistentMass(s, L)
                      : Mat12(lumpedMassDiagonal(s, L, rotaryScale).asDiagonal());
  return eigenfrequencies(K, M).maxCoeff();
}

// Free-free linear bar: K = EA/L [1 -1; -1 1], M = rho A L/6 [2 1; 1 2]; mode (1, -1):
//   omega^2 = (2 EA/L) / (rho A L/6) = 12 E/(rho L^2).
double closedFormAxialOmegaMax(const Section& s, double L) {
  return std::sqrt(12.0 * s.E / s.rho) / L;
}

// Free-free Hermite beam: the flexible modes are the symmetric (w_a = w_b, w'_a = -w'_b) and the
// antisymmetric (w_a = -w_b, w'_a = w'_b) ones. Each 2-D subspace holds one rigid mode (translation,
// resp. rotation about the midpoint) and one flexible mode: the 2x2 problem det(K - omega^2 M) = 0 gives
// omega^2 = 720 EI/(rho A L^4) (symmetric) and 8400 EI/(rho A L^4) (antisymmetric, the largest).
double closedFormBendingOmegaMax(const Section& s, double L, double I) {
  return std::sqrt(8400.0 * s.E * I / (s.rho * s.A * L * L * L * L));
}

}  // namespace enamel::beam
