#include "laws/cohesive.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace enamel::cohesive {

double Law::delta0() const { return sigma0 / k; }
double Law::softeningLength() const { return softeningOverDelta0 * delta0(); }
// delta1 = Gamma/sigma0 + (delta0 - L)/2: with L = delta0 (the default) the correction is +0.0 exactly, so
// delta1 = Gamma/sigma0 bit for bit.
double Law::delta1() const { return Gamma / sigma0 + 0.5 * (delta0() - softeningLength()); }
double Law::deltaf() const { return delta1() + softeningLength(); }

Law makeLaw(double k, double sigma0, double Gamma, double softeningOverDelta0, double shearStrengthRatio) {
  // !(x > 0) also rejects NaN.
  if (!(k > 0.0)) throw std::invalid_argument("cohesive law: stiffness k must be > 0, got " + std::to_string(k));
  if (!(sigma0 > 0.0))
    throw std::invalid_argument("cohesive law: strength sigma0 must be > 0, got " + std::to_string(sigma0));
  if (!(Gamma > 0.0))
    throw std::invalid_argument("cohesive law: fracture energy Gamma must be > 0, got " + std::to_string(Gamma));
  // Trapezoid needs delta1 >= delta0, i.e. Gamma >= sigma0^2/k (equality: triangle).
  if (Gamma < sigma0 * sigma0 / k)
    throw std::invalid_argument("cohesive law: fracture energy Gamma = " + std::to_string(Gamma) +
                                " must be >= sigma0^2/k = " + std::to_string(sigma0 * sigma0 / k) +
                                " (plateau end delta1 = Gamma/sigma0 below elastic limit delta0 = sigma0/k)");
  // delta1 >= delta0  <=>  L/delta0 <= 2 G - 1 (the triangle at equality; slack for round-off in G).
  const double maxSoftening = 2.0 * Gamma * k / (sigma0 * sigma0) - 1.0;
  if (!(softeningOverDelta0 > 0.0) || softeningOverDelta0 > maxSoftening * (1.0 + 1e-12))
    throw std::invalid_argument("cohesive law: softening_over_delta0 = " + std::to_string(softeningOverDelta0) +
                                " must be in (0, 2 Gamma k/sigma0^2 - 1] = (0, " + std::to_string(maxSoftening) +
                                "] (plateau end delta1 below elastic limit delta0)");
  if (!(shearStrengthRatio > 0.0) || shearStrengthRatio > kMaxShearStrengthRatio)
    throw std::invalid_argument("cohesive law: shear_strength_ratio = " + std::to_string(shearStrengthRatio) +
                                " must be in (0, " + std::to_string(kMaxShearStrengthRatio) + "]");
  // 1/(1*1) = 1 exactly: beta = 1 multiplies the shear part of lambda^2 by 1, which changes no bit.
  return Law{k, sigma0, Gamma, softeningOverDelta0, shearStrengthRatio,
             1.0 / (shearStrengthRatio * shearStrengthRatio)};
}

// T(lambda) = k lambda                          for lambda <= delta0
//           = sigma0                            for delta0 < lambda <= delta1
//           = sigma0 (deltaf - lambda)/L        for delta1 < lambda < deltaf   (L = deltaf - delta1; default delta0)
//           = 0                                 for lambda >= deltaf
double envelopeTraction(const Law& law, double lambda) {
  const double d0 = law.delta0(), d1 = law.delta1(), df = law.deltaf();
  if (lambda <= d0) return law.k * lambda;
  if (lambda <= d1) return law.sigma0;
  if (lambda < df) return law.sigma0 * (df - lambda) / law.softeningLength();
  return 0.0;
}

// lambda = sqrt(<dn>_+^2 + dt1^2 + dt2^2)
double effectiveSeparation(const Vec3& openingLocal) {
  const double dnPos = std::max(openingLocal(0), 0.0);
  return std::sqrt(dnPos * dnPos + openingLocal(1) * openingLocal(1) + openingLocal(2) * openingLocal(2));
}

namespace {
// lambda^2 = <dn>_+^2 + dt1^2 w + dt2^2 w, w = 1/beta^2; in the order of the sum above, so that w = 1 gives its
// bits (each product by 1 is exact).
double effectiveSeparationSq(const Law& law, const Vec3& o) {
  const double dnPos = std::max(o(0), 0.0);
  return dnPos * dnPos + o(1) * o(1) * law.shearWeight + o(2) * o(2) * law.shearWeight;
}
// |(<dn>_+, dt1, dt2)|^2
double positiveOpeningSq(const Vec3& o) {
  const double dnPos = std::max(o(0), 0.0);
  return dnPos * dnPos + o(1) * o(1) + o(2) * o(2);
}
}  // namespace

// lambda = sqrt(<dn>_+^2 + (dt1^2 + dt2^2)/beta^2)
double effectiveSeparation(const Law& law, const Vec3& openingLocal) {
  return std::sqrt(effectiveSeparationSq(law, openingLocal));
}

// m = |(<dn>_+, dt1, dt2)|^2 / lambda^2 (1 at beta = 1 and at a zero opening)
double modeFactor(const Law& law, const Vec3& openingLocal) {
  const double lambdaSq = effectiveSeparationSq(law, openingLocal);
  if (law.isotropic() || lambdaSq == 0.0) return 1.0;
  return positiveOpeningSq(openingLocal) / lambdaSq;
}

// S = T(lambdaMax)/lambdaMax, with S = k on the elastic branch (also at lambdaMax = 0) and S = 0 once failed.
double secantStiffness(const Law& law, double lambdaMax) {
  if (law.k * lambdaMax <= law.sigma0) return law.k;  // lambdaMax <= delta0, without a division (hot path)
  if (lambdaMax >= law.deltaf()) return 0.0;
  return envelopeTraction(law, lambdaMax) / lambdaMax;
}

// lambdaMax <- max(lambdaMax, lambda), except on the elastic track (below)
// t = S(lambdaMax) (<dn>_+, dt1, dt2) + (k min(dn, 0), 0, 0)
// (S (<dn>_+, dt1, dt2) = T/lambda (<dn>_+, dt1, dt2) with T = S lambda, without dividing by lambda.)
// Elastic track: while k lambdaMax <= sigma0 and (k lambda)^2 <= kElasticTrack sigma0^2, S = k whatever the
// history, so lambda (a square root) is not taken and lambdaMax is left as it is. lambdaMax then differs from
// the largest lambda only while both are below delta0, where S = k, the damage and the dissipated energy are 0
// and the interface is neither inelastic nor failed: the traction, and everything computed from lambdaMax, are
// the same as with the plain maximum (proof: the largest lambda is either one that passed the track's bound,
// and so was recorded, or one below it; tests/cpp/test_cohesive.cpp checks it along random paths).
// lambda^2 = <dn>_+^2 + (dt1^2 + dt2^2)/beta^2 (effectiveSeparationSq), so the track's bound is on lambda of
// the mixed-mode law: S = k below it in every mode, whatever beta.
Vec3 computeTraction(const Law& law, const Vec3& openingLocal, double& lambdaMax) {
  const double lambdaSq = effectiveSeparationSq(law, openingLocal);
  const double dn = openingLocal(0);
  if (law.k * lambdaMax <= law.sigma0 && (law.k * law.k) * lambdaSq <= kElasticTrack * (law.sigma0 * law.sigma0))
    return Vec3(law.k * std::max(dn, 0.0) + law.k * std::min(dn, 0.0), law.k * openingLocal(1), law.k * openingLocal(2));
  const double lambda = std::sqrt(lambdaSq);  // = effectiveSeparation(law, openingLocal), the same operations
  lambdaMax = std::max(lambdaMax, lambda);
  const double S = secantStiffness(law, lambdaMax);
  return Vec3(S * std::max(dn, 0.0) + law.k * std::min(dn, 0.0), S * openingLocal(1), S * openingLocal(2));
}

// W_stored = 0.5 S |(<dn>_+, dt1, dt2)|^2 + 0.5 k <-dn>_+^2; at beta = 1 written 0.5 S lambda^2 as before the
// key (lambda * lambda is not always the sum under the root, bit for bit).
double storedEnergyDensity(const Law& law, const Vec3& openingLocal, double lambdaMax) {
  const double lambda = effectiveSeparation(law, openingLocal);
  const double S = secantStiffness(law, std::max(lambdaMax, lambda));
  const double dnNeg = std::max(-openingLocal(0), 0.0);
  const double opened = law.isotropic() ? 0.5 * S * lambda * lambda : 0.5 * S * positiveOpeningSq(openingLocal);
  return opened + 0.5 * law.k * dnNeg * dnNeg;
}

// W_diss(lambdaMax) = int_0^lambdaMax T dlambda - 0.5 T(lambdaMax) lambdaMax; piecewise:
//   elastic:   0
//   plateau:   0.5 sigma0 delta0 + sigma0 (lambdaMax - delta0) - 0.5 sigma0 lambdaMax
//   softening: Gamma - 0.5 T (deltaf - lambdaMax) - 0.5 T lambdaMax = Gamma - 0.5 T deltaf
//   failed:    Gamma
double dissipatedEnergyDensity(const Law& law, double lambdaMax) {
  const double d0 = law.delta0(), d1 = law.delta1(), df = law.deltaf();
  if (lambdaMax <= d0) return 0.0;
  if (lambdaMax <= d1) return 0.5 * law.sigma0 * (lambdaMax - d0);
  if (lambdaMax < df) return law.Gamma - 0.5 * envelopeTraction(law, lambdaMax) * df;
  return law.Gamma;
}

// m (phi(after) - phi(before)), phi = dissipatedEnergyDensity
double dissipationIncrement(const Law& law, const Vec3& openingLocal, double lambdaMaxBefore, double lambdaMaxAfter) {
  if (!(lambdaMaxAfter > lambdaMaxBefore)) return 0.0;
  const double dPhi = dissipatedEnergyDensity(law, lambdaMaxAfter) - dissipatedEnergyDensity(law, lambdaMaxBefore);
  return dPhi == 0.0 ? 0.0 : modeFactor(law, openingLocal) * dPhi;
}

// D = 1 - S/k
double damage(const Law& law, double lambdaMax) { return 1.0 - secantStiffness(law, lambdaMax) / law.k; }
bool isInelastic(const Law& law, double lambdaMax) { return lambdaMax > law.delta0(); }
bool isFailed(const Law& law, double lambdaMax) { return lambdaMax >= law.deltaf(); }

Mat3 makeFrame(const Vec3& normal) {
  const Vec3 n = normal.normalized();
  Vec3 t1 = Vec3::UnitX() - n.x() * n;  // e_x minus its normal part
  if (t1.norm() < 1e-8) t1 = Vec3::UnitY() - n.y() * n;
  t1.normalize();
  Mat3 frame;
  frame.row(0) = n.transpose();
  frame.row(1) = t1.transpose();
  frame.row(2) = n.cross(t1).transpose();
  return frame;
}

// delta = (uB + thB x rB) - (uA + thA x rA)
Vec3 computeOpening(const InterfaceGeometry& g, const Vec3& uA, const Vec3& thA, const Vec3& uB, const Vec3& thB) {
  return (uB + thB.cross(g.armB)) - (uA + thA.cross(g.armA));
}

// t = traction(R delta), F_B = -A R^T t
Vec3 computeInterfaceForceOnB(const Law& law, const InterfaceGeometry& g, const Vec3& uA, const Vec3& thA,
                              const Vec3& uB, const Vec3& thB, double& lambdaMax) {
  const Vec3 openingLocal = g.frame * computeOpening(g, uA, thA, uB, thB);
  const Vec3 tLocal = computeTraction(law, openingLocal, lambdaMax);
  const Vec3 tGlobal = g.frame.transpose() * tLocal;  // evaluated first: Eigen would fold -area into the product
  return -g.area * tGlobal;
}

// B: (F_B, rB x F_B);  A: F_A = -F_B, (F_A, rA x F_A)
Wrench wrenchOnSide(const InterfaceGeometry& g, const Vec3& forceOnB, bool sideB) {
  if (sideB) return Wrench{forceOnB, g.armB.cross(forceOnB)};
  const Vec3 forceA = -forceOnB;
  return Wrench{forceA, g.armA.cross(forceA)};
}

SliceInterface packInSlice(const InterfaceGeometry& g) {
  const Vec3 n = g.frame.row(0).transpose();
  if (n.x() != 0.0 || g.armA.x() != 0.0 || g.armB.x() != 0.0 ||
      g.frame.row(1).transpose() != Vec3::UnitX() || g.frame.row(2).transpose() != n.cross(Vec3::UnitX()))
    throw std::invalid_argument("interface geometry is not in one yz-slice (normal or arm with an x part)");
  return SliceInterface{n.y(), n.z(), g.armA.y(), g.armA.z(), g.armB.y(), g.armB.z(), g.area};
}

// delta = (uB + thB x rB) - (uA + thA x rA) with r = (0, ry, rz): thB x rB = (thy rz - thz ry, -thx rz, thx ry)
// (the products the general form multiplies by the arms' zero x left out).
Vec3 computeOpening(const SliceInterface& g, const Vec3& uA, const Vec3& thA, const Vec3& uB, const Vec3& thB) {
  const double ox = (uB.x() + (thB.y() * g.armBz - thB.z() * g.armBy)) - (uA.x() + (thA.y() * g.armAz - thA.z() * g.armAy));
  const double oy = (uB.y() + (-(thB.x() * g.armBz))) - (uA.y() + (-(thA.x() * g.armAz)));
  const double oz = (uB.z() + thB.x() * g.armBy) - (uA.z() + thA.x() * g.armAy);
  return Vec3(ox, oy, oz);
}

// local opening (n . delta, delta_x, t2 . delta) with t2 = (0, nz, -ny)
Vec3 localOpening(const SliceInterface& g, const Vec3& opening) {
  return Vec3(g.ny * opening.y() + g.nz * opening.z(), opening.x(), g.nz * opening.y() + (-g.ny) * opening.z());
}

// F_B = -A (n t_n + e_x t_1 + t2 t_2)
Vec3 forceOnBOfTraction(const SliceInterface& g, const Vec3& t) {
  return -g.area * Vec3(t(1), g.ny * t(0) + g.nz * t(2), g.nz * t(0) + (-g.ny) * t(2));
}

// The opening, its local form, the traction and the force as above. Every product the general form multiplies
// by an exact zero is left out: the sums keep their order, so the result is the general form's bit for bit (a
// zero product adds nothing exactly, without FMA contraction).
Vec3 computeInterfaceForceOnB(const Law& law, const SliceInterface& g, const Vec3& uA, const Vec3& thA,
                              const Vec3& uB, const Vec3& thB, double& lambdaMax) {
  const Vec3 t = computeTraction(law, localOpening(g, computeOpening(g, uA, thA, uB, thB)), lambdaMax);
  return forceOnBOfTraction(g, t);
}

// t = k R delta in every direction while S = k (tension, shear and contact alike), so F_B = -A R^T k R delta
// = -k A delta (R orthonormal).
Vec3 elasticForceOnB(const Law& law, const SliceInterface& g, const Vec3& uA, const Vec3& thA, const Vec3& uB,
                     const Vec3& thB) {
  return -(law.k * g.area) * computeOpening(g, uA, thA, uB, thB);
}

// B: (F_B, rB x F_B);  A: F_A = -F_B, (F_A, rA x F_A)
// r x F with r = (0, ry, rz) written out: (ry Fz - rz Fy, rz Fx, -ry Fx), the general cross product less its
// products by the zero x of the arm (equal to it, up to the sign of a zero).
Wrench wrenchOnSide(const SliceInterface& g, const Vec3& forceOnB, bool sideB) {
  const double ry = sideB ? g.armBy : g.armAy, rz = sideB ? g.armBz : g.armAz;
  const double fx = sideB ? forceOnB.x() : -forceOnB.x(), fy = sideB ? forceOnB.y() : -forceOnB.y(),
               fz = sideB ? forceOnB.z() : -forceOnB.z();
  return Wrench{Vec3(fx, fy, fz), Vec3(ry * fz - rz * fy, rz * fx, -(ry * fx))};
}

// F_B as above, then the wrench on each side
NodalWrench computeInterfaceForces(const Law& law, const InterfaceGeometry& g, const Vec3& uA, const Vec3& thA,
                                   const Vec3& uB, const Vec3& thB, double& lambdaMax) {
  const Vec3 forceB = computeInterfaceForceOnB(law, g, uA, thA, uB, thB, lambdaMax);
  const Wrench onA = wrenchOnSide(g, forceB, false), onB = wrenchOnSide(g, forceB, true);
  return NodalWrench{onA.force, onA.moment, onB.force, onB.moment};
}

// delta = Bq with B = [-I, [rA]x, I, -[rB]x] (theta x r = -[r]x theta), q = (uA, thA, uB, thB);
// undamaged traction is k delta in every direction (tension: S = k; compression: contact k dn), so
// f = -A B^T R^T (k R delta) = -k A B^T B q  =>  K = k A B^T B.
Eigen::Matrix<double, 12, 12> elasticStiffness(const Law& law, const InterfaceGeometry& g) {
  auto skew = [](const Vec3& r) {
    Mat3 s;
    s << 0.0, -r.z(), r.y(), r.z(), 0.0, -r.x(), -r.y(), r.x(), 0.0;
    return s;
  };
  Eigen::Matrix<double, 3, 12> B;
  B << -Mat3::Identity(), skew(g.armA), Mat3::Identity(), -skew(g.armB);
  return law.k * g.area * (B.transpose() * B);
}

}  // namespace enamel::cohesive
