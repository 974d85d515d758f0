#include "laws/cohesive_law.hpp"

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

}  // namespace enamel::cohesive
