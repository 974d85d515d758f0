// Tests of the symmetric trapezoidal cohesive law (solver/lib/laws/cohesive_law) and the rigid-arm interface
// element (solver/lib/geometry/cohesive).
#include "geometry/cohesive.hpp"
#include "laws/cohesive_law.hpp"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

using namespace enamel::cohesive;

namespace {

// Normalised values (docs/model.md, units): Er/(k d) = 10 -> k = 0.1; delta0/d = 1e-3 -> sigma0 = 1e-4;
// Gamma k / sigma0^2 = 3 -> Gamma = 3e-7. So delta0 = 1e-3, delta1 = 3e-3, deltaf = 4e-3.
const Law kLaw = makeLaw(0.1, 1e-4, 3e-7);

// Round-off tolerance for closed-form quantities evaluated with a handful of flops.
constexpr double kRoundoff = 1e-12;
// Energy from trapezoid-rule integration of the work: exact on linear pieces, O(h^2) at kinks and on
// curved pieces; 1e-6 relative is the accuracy asked of the law's integral.
constexpr double kWorkTol = 1e-6;

// Work int t . d(opening) along the straight leg from -> to in local opening space, trapezoid rule with n
// steps, updating lambdaMax and the traction at the start of the leg (tPrev).
double integrateWork(const Law& law, const Vec3& from, const Vec3& to, int n, double& lambdaMax, Vec3& tPrev) {
  double work = 0.0;
  Vec3 gPrev = from;
  for (int i = 1; i <= n; ++i) {
    const Vec3 g = from + (to - from) * (double(i) / n);
    const Vec3 t = computeTraction(law, g, lambdaMax);
    work += 0.5 * (tPrev + t).dot(g - gPrev);
    tPrev = t;
    gPrev = g;
  }
  return work;
}

// Monotonic radial opening lambda * e (e unit, e_n >= 0) from 0 to 1.2 deltaf; each leg of the path ends on a
// kink of the envelope (delta0, delta1, deltaf), so the trapezoid rule is exact on every leg.
double monotonicWork(const Law& law, const Vec3& e, double& lambdaMax) {
  const std::vector<double> breaks = {0.0, law.delta0(), law.delta1(), law.deltaf(), 1.2 * law.deltaf()};
  Vec3 tPrev = computeTraction(law, Vec3::Zero(), lambdaMax);
  double work = 0.0;
  for (size_t b = 1; b < breaks.size(); ++b)
    work += integrateWork(law, breaks[b - 1] * e, breaks[b] * e, 1000, lambdaMax, tPrev);
  return work;
}

Vec3 randomVec(std::mt19937& rng, double scale) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  return scale * Vec3(u(rng), u(rng), u(rng));
}

// Interface between random rod centres xA, xB with a common Voronoi-edge midpoint m near their midpoint.
InterfaceGeometry randomGeometry(std::mt19937& rng, Vec3& xA, Vec3& xB) {
  xA = randomVec(rng, 2.0);
  xB = xA + randomVec(rng, 1.0);
  const Vec3 m = 0.5 * (xA + xB) + randomVec(rng, 0.2);
  return InterfaceGeometry{makeFrame(xB - xA), m - xA, m - xB, 0.3 * 0.577};
}

}  // namespace

TEST(Cohesive, EnvelopeShapeAndArea) {
  const Law& L = kLaw;
  EXPECT_NEAR(L.delta0(), 1e-3, kRoundoff * 1e-3);
  EXPECT_NEAR(L.delta1(), 3e-3, kRoundoff * 3e-3);
  EXPECT_NEAR(L.deltaf(), 4e-3, kRoundoff * 4e-3);
  EXPECT_DOUBLE_EQ(envelopeTraction(L, 0.0), 0.0);
  EXPECT_NEAR(envelopeTraction(L, 0.5 * L.delta0()), 0.5 * L.sigma0, kRoundoff * L.sigma0);
  EXPECT_NEAR(envelopeTraction(L, L.delta0()), L.sigma0, kRoundoff * L.sigma0);
  EXPECT_DOUBLE_EQ(envelopeTraction(L, 0.5 * (L.delta0() + L.delta1())), L.sigma0);
  EXPECT_DOUBLE_EQ(envelopeTraction(L, L.delta1()), L.sigma0);
  EXPECT_NEAR(envelopeTraction(L, L.delta1() + 0.25 * L.delta0()), 0.75 * L.sigma0, kRoundoff * L.sigma0);
  EXPECT_DOUBLE_EQ(envelopeTraction(L, L.deltaf()), 0.0);
  EXPECT_DOUBLE_EQ(envelopeTraction(L, 2.0 * L.deltaf()), 0.0);
  // Continuity just past each kink (jump at most slope * eps; eps = 1e-9 deltaf).
  const double eps = 1e-9 * L.deltaf();
  for (double kink : {L.delta0(), L.delta1(), L.deltaf()})
    EXPECT_NEAR(envelopeTraction(L, kink + eps), envelopeTraction(L, kink), 2.0 * L.k * eps) << kink;
  // Area = Gamma: exact piecewise trapezoid areas.
  const double area = 0.5 * L.sigma0 * L.delta0() + L.sigma0 * (L.delta1() - L.delta0()) +
                      0.5 * L.sigma0 * (L.deltaf() - L.delta1());
  EXPECT_NEAR(area, L.Gamma, kRoundoff * L.Gamma);
}

TEST(Cohesive, EffectiveSeparationIgnoresCompression) {
  EXPECT_DOUBLE_EQ(effectiveSeparation(Vec3(3.0, 4.0, 0.0)), 5.0);
  EXPECT_DOUBLE_EQ(effectiveSeparation(Vec3(-7.0, 3.0, 4.0)), 5.0);
  EXPECT_DOUBLE_EQ(effectiveSeparation(Vec3(-7.0, 0.0, 0.0)), 0.0);
}

TEST(Cohesive, MonotonicOpeningDissipatesGammaInEveryMode) {
  const std::vector<std::pair<const char*, Vec3>> dirs = {
      {"normal", Vec3(1, 0, 0)}, {"shear t1", Vec3(0, 1, 0)}, {"shear t2", Vec3(0, 0, 1)},
      {"mixed", Vec3(0.6, -0.48, 0.64).normalized()}};
  for (const auto& [name, e] : dirs) {
    double lambdaMax = 0.0;
    const double work = monotonicWork(kLaw, e, lambdaMax);
    EXPECT_NEAR(work, kLaw.Gamma, kWorkTol * kLaw.Gamma) << name;
    EXPECT_TRUE(isFailed(kLaw, lambdaMax)) << name;
    EXPECT_DOUBLE_EQ(damage(kLaw, lambdaMax), 1.0) << name;
    // After failure nothing is stored, all the work is dissipated: exactly Gamma (1e-12 relative).
    EXPECT_NEAR(storedEnergyDensity(kLaw, 1.2 * kLaw.deltaf() * e, lambdaMax), 0.0, 1e-12 * kLaw.Gamma) << name;
    EXPECT_NEAR(dissipatedEnergyDensity(kLaw, lambdaMax), kLaw.Gamma, 1e-12 * kLaw.Gamma) << name;
    EXPECT_NEAR(dissipatedEnergyDensity(kLaw, kLaw.deltaf()), kLaw.Gamma, 1e-12 * kLaw.Gamma) << name;
  }
}

TEST(Cohesive, TriangleLawAllowedAndDissipatesGamma) {
  // Gamma = sigma0^2/k: delta1 = delta0, no plateau.
  const Law tri = makeLaw(0.1, 1e-4, 1e-4 * 1e-4 / 0.1);
  EXPECT_NEAR(tri.delta1(), tri.delta0(), kRoundoff * tri.delta0());
  double lambdaMax = 0.0;
  EXPECT_NEAR(monotonicWork(tri, Vec3(0, 1, 0), lambdaMax), tri.Gamma, kWorkTol * tri.Gamma);
  EXPECT_NEAR(dissipatedEnergyDensity(tri, lambdaMax), tri.Gamma, 1e-12 * tri.Gamma);
}

TEST(Cohesive, DissipatedEnergyIsContinuousAndMonotonic) {
  // Continuity at each kink within slope * eps; the steepest slope, on the softening branch, is
  // d/dlambda (Gamma - 0.5 T deltaf) = 0.5 sigma0 deltaf / delta0 (plus 1% for round-off).
  const double eps = 1e-9 * kLaw.deltaf();
  const double maxSlope = 0.5 * kLaw.sigma0 * kLaw.deltaf() / kLaw.delta0();
  for (double kink : {kLaw.delta0(), kLaw.delta1(), kLaw.deltaf()})
    EXPECT_NEAR(dissipatedEnergyDensity(kLaw, kink - eps), dissipatedEnergyDensity(kLaw, kink), 1.01 * maxSlope * eps);
  EXPECT_DOUBLE_EQ(dissipatedEnergyDensity(kLaw, 0.7 * kLaw.delta0()), 0.0);
  double prev = 0.0;
  for (int i = 0; i <= 200; ++i) {
    const double w = dissipatedEnergyDensity(kLaw, 1.2 * kLaw.deltaf() * i / 200.0);
    EXPECT_GE(w, prev) << i;
    prev = w;
  }
}

TEST(Cohesive, SecantUnloadingAndReloadingWithoutExtraDamage) {
  const Vec3 e = Vec3(0.5, 0.7, -0.3).normalized();
  for (double lambdaU : {0.5 * (kLaw.delta0() + kLaw.delta1()), 0.5 * (kLaw.delta1() + kLaw.deltaf())}) {
    double lambdaMax = 0.0;
    computeTraction(kLaw, lambdaU * e, lambdaMax);
    ASSERT_DOUBLE_EQ(lambdaMax, lambdaU);
    const double S = envelopeTraction(kLaw, lambdaU) / lambdaU;
    const double damageU = damage(kLaw, lambdaMax);
    EXPECT_NEAR(damageU, 1.0 - S / kLaw.k, kRoundoff);
    // Unload to the origin, then reload to the same point: t = S * opening throughout (1e-12 of sigma0).
    for (int i = 0; i <= 40; ++i) {
      const double s = (i <= 20) ? 1.0 - i / 20.0 : (i - 20) / 20.0;
      const Vec3 g = s * lambdaU * e;
      const Vec3 t = computeTraction(kLaw, g, lambdaMax);
      EXPECT_LE((t - S * g).norm(), kRoundoff * kLaw.sigma0) << "s = " << s;
      EXPECT_DOUBLE_EQ(lambdaMax, lambdaU) << "no extra damage, s = " << s;
      if (i == 20) {
        EXPECT_EQ(t.norm(), 0.0) << "zero traction at zero opening";
      }
    }
    EXPECT_DOUBLE_EQ(damage(kLaw, lambdaMax), damageU);
    // Back on the envelope at the reload point, and following it beyond.
    Vec3 t = computeTraction(kLaw, lambdaU * e, lambdaMax);
    EXPECT_NEAR(t.norm(), envelopeTraction(kLaw, lambdaU), kRoundoff * kLaw.sigma0);
    t = computeTraction(kLaw, 1.05 * lambdaU * e, lambdaMax);
    EXPECT_DOUBLE_EQ(lambdaMax, 1.05 * lambdaU);
    EXPECT_NEAR(t.norm(), envelopeTraction(kLaw, 1.05 * lambdaU), kRoundoff * kLaw.sigma0);
  }
}

TEST(Cohesive, CompressionNeverDamages) {
  double lambdaMax = 0.0;
  const double dn = -100.0 * kLaw.deltaf();
  const Vec3 t = computeTraction(kLaw, Vec3(dn, 0.0, 0.0), lambdaMax);
  EXPECT_EQ(lambdaMax, 0.0);
  EXPECT_DOUBLE_EQ(t(0), kLaw.k * dn);
  EXPECT_EQ(t(1), 0.0);
  EXPECT_EQ(t(2), 0.0);
  EXPECT_FALSE(isInelastic(kLaw, lambdaMax));
  EXPECT_EQ(damage(kLaw, lambdaMax), 0.0);
  EXPECT_DOUBLE_EQ(storedEnergyDensity(kLaw, Vec3(dn, 0.0, 0.0), lambdaMax), 0.5 * kLaw.k * dn * dn);
}

TEST(Cohesive, ContactActsAfterFailure) {
  double lambdaMax = 1.5 * kLaw.deltaf();
  ASSERT_TRUE(isFailed(kLaw, lambdaMax));
  const Vec3 g(-2.0 * kLaw.delta0(), 3.0 * kLaw.delta0(), -kLaw.delta0());
  Vec3 t = computeTraction(kLaw, g, lambdaMax);
  EXPECT_DOUBLE_EQ(t(0), kLaw.k * g(0));
  EXPECT_EQ(t(1), 0.0) << "no shear transmitted once failed";
  EXPECT_EQ(t(2), 0.0);
  EXPECT_DOUBLE_EQ(lambdaMax, 1.5 * kLaw.deltaf());
  t = computeTraction(kLaw, Vec3(0.5 * kLaw.delta0(), 0.1 * kLaw.delta0(), 0.0), lambdaMax);
  EXPECT_EQ(t.norm(), 0.0) << "no traction in tension once failed";
}

TEST(Cohesive, WorkEqualsStoredPlusDissipatedAlongLoadingUnloadingPath) {
  // Non-proportional path in local opening space (units of delta0 = 1e-3): elastic, softening, unloading into
  // compression with shear, reloading past the old lambdaMax in another direction, partial unloading,
  // failure, then contact after failure.
  const double d = kLaw.delta0();
  const std::vector<Vec3> path = {Vec3::Zero(),
                                  0.4 * d * Vec3(1.0, 0.5, 0.0),
                                  3.5 * d * Vec3(1.0, 1.0, 0.5).normalized(),
                                  d * Vec3(-0.5, 0.2, -0.1),
                                  d * Vec3(0.3, -3.7, 0.5),
                                  d * Vec3(0.2, -1.0, 0.0),
                                  d * Vec3(2.0, 5.0, -1.0),
                                  d * Vec3(-1.0, 0.5, 0.2)};
  double lambdaMax = 0.0, work = 0.0;
  Vec3 tPrev = computeTraction(kLaw, path[0], lambdaMax);
  for (size_t leg = 1; leg < path.size(); ++leg) {
    work += integrateWork(kLaw, path[leg - 1], path[leg], 20000, lambdaMax, tPrev);
    const double stored = storedEnergyDensity(kLaw, path[leg], lambdaMax);
    const double dissipated = dissipatedEnergyDensity(kLaw, lambdaMax);
    EXPECT_NEAR(work, stored + dissipated, kWorkTol * work) << "after leg " << leg;
  }
  EXPECT_TRUE(isFailed(kLaw, lambdaMax));
  const double dn = path.back()(0);
  EXPECT_NEAR(work, kLaw.Gamma + 0.5 * kLaw.k * dn * dn, kWorkTol * work);
}

TEST(Cohesive, FrameIsRightHandedOrthonormal) {
  for (const Vec3& n : {Vec3(0, 1, 0), Vec3(0, 0.3, -2.0), Vec3(1, 0, 0), Vec3(0.2, -0.5, 0.7)}) {
    const Mat3 R = makeFrame(n);
    EXPECT_LE((R * R.transpose() - Mat3::Identity()).norm(), kRoundoff);
    EXPECT_NEAR(R.determinant(), 1.0, kRoundoff);
    EXPECT_LE((R.row(0).transpose() - n.normalized()).norm(), kRoundoff);
  }
}

TEST(Cohesive, NormalOpeningPullsNodesTogether) {
  std::mt19937 rng(7);
  Vec3 xA, xB;
  const InterfaceGeometry g = randomGeometry(rng, xA, xB);
  const Vec3 n = g.frame.row(0).transpose();
  double lambdaMax = 0.0;
  const Vec3 zero = Vec3::Zero();
  const double dn = 0.5 * kLaw.delta0();
  const NodalWrench w = computeInterfaceForces(kLaw, g, zero, zero, dn * n, zero, lambdaMax);
  // Elastic: |F| = k * dn * area along -n on B (1e-12 relative).
  EXPECT_LE((w.forceB + kLaw.k * dn * g.area * n).norm(), kRoundoff * kLaw.k * dn * g.area);
  EXPECT_EQ(lambdaMax, 0.0) << "below delta0 the history is not recorded (the elastic track)";
  const double dnBeyond = 1.5 * kLaw.delta0();
  computeInterfaceForces(kLaw, g, zero, zero, dnBeyond * n, zero, lambdaMax);
  EXPECT_NEAR(lambdaMax, dnBeyond, kRoundoff * dnBeyond) << "beyond it, it is";
}

TEST(Cohesive, RigidRotationOpensNothing) {
  std::mt19937 rng(1);
  for (int trial = 0; trial < 50; ++trial) {
    Vec3 xA, xB;
    const InterfaceGeometry g = randomGeometry(rng, xA, xB);
    const Vec3 p = randomVec(rng, 1.0), w = randomVec(rng, 1.0), c = randomVec(rng, 1.0);
    // Rigid motion u = c + w x (x - p), th = w at both nodes.
    const Vec3 uA = c + w.cross(xA - p), uB = c + w.cross(xB - p);
    const Vec3 opening = computeOpening(g, uA, w, uB, w);
    EXPECT_LE(opening.cwiseAbs().maxCoeff(), 1e-14) << "trial " << trial;  // round-off of O(1) values
    double lambdaMax = 0.0;
    const NodalWrench f = computeInterfaceForces(kLaw, g, uA, w, uB, w, lambdaMax);
    // Force from a round-off opening: at most k * area * 1e-14.
    const double fTol = kLaw.k * g.area * 1e-14;
    EXPECT_LE(f.forceA.norm(), fTol);
    EXPECT_LE(f.forceB.norm(), fTol);
    EXPECT_LE(f.momentA.norm(), 4.0 * fTol);  // arms are shorter than 2
    EXPECT_LE(f.momentB.norm(), 4.0 * fTol);
    // The linearised stiffness has the rigid motion in its null space (1e-12 of k * area * |q|).
    Eigen::Matrix<double, 12, 1> q;
    q << uA, w, uB, w;
    EXPECT_LE((elasticStiffness(kLaw, g) * q).norm(), kRoundoff * kLaw.k * g.area * q.norm());
  }
}

TEST(Cohesive, ForcesBalanceAndConserveAngularMomentum) {
  std::mt19937 rng(2);
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  for (int trial = 0; trial < 200; ++trial) {
    Vec3 xA, xB;
    const InterfaceGeometry g = randomGeometry(rng, xA, xB);
    // Displacements from elastic to failed; rotations scaled so that theta x arm is comparable.
    const double s = 1.5 * kLaw.deltaf();
    const Vec3 uA = randomVec(rng, s), thA = randomVec(rng, s), uB = randomVec(rng, s), thB = randomVec(rng, s);
    double lambdaMax = u01(rng) * kLaw.deltaf();
    const NodalWrench f = computeInterfaceForces(kLaw, g, uA, thA, uB, thB, lambdaMax);
    EXPECT_EQ((f.forceA + f.forceB).norm(), 0.0) << "equal and opposite by construction";
    const Vec3 L = xA.cross(f.forceA) + f.momentA + xB.cross(f.forceB) + f.momentB;
    const double scale = (xA.norm() + xB.norm() + g.armA.norm() + g.armB.norm()) * f.forceA.norm();
    EXPECT_LE(L.norm(), kRoundoff * scale) << "trial " << trial;  // 1e-12 relative
  }
}

TEST(Cohesive, ElasticStiffnessMatchesForcesInElasticRange) {
  std::mt19937 rng(3);
  for (int trial = 0; trial < 200; ++trial) {
    Vec3 xA, xB;
    const InterfaceGeometry g = randomGeometry(rng, xA, xB);
    // |opening| <= s*sqrt(3)*(2 + 2*max|arm|) < 0.8 delta0, since |arm| <= sqrt(3)/2 + 0.2*sqrt(3) < 1.22.
    const double s = 0.1 * kLaw.delta0();
    const Vec3 uA = randomVec(rng, s), thA = randomVec(rng, s), uB = randomVec(rng, s), thB = randomVec(rng, s);
    double lambdaMax = 0.0;
    const NodalWrench f = computeInterfaceForces(kLaw, g, uA, thA, uB, thB, lambdaMax);
    ASSERT_LE(lambdaMax, kLaw.delta0()) << "test meant for the elastic range";
    Eigen::Matrix<double, 12, 1> q, fv;
    q << uA, thA, uB, thB;
    fv << f.forceA, f.momentA, f.forceB, f.momentB;
    const Eigen::Matrix<double, 12, 12> K = elasticStiffness(kLaw, g);
    EXPECT_LE((K * q + fv).norm(), 1e-10 * fv.norm()) << "trial " << trial;
    EXPECT_LE((K - K.transpose()).norm(), kRoundoff * K.norm());
  }
}

TEST(Cohesive, MakeLawRejectsBadParameters) {
  EXPECT_THROW(makeLaw(0.1, 1e-4, 0.99e-7), std::invalid_argument);  // Gamma < sigma0^2/k = 1e-7
  EXPECT_THROW(makeLaw(0.0, 1e-4, 3e-7), std::invalid_argument);
  EXPECT_THROW(makeLaw(0.1, -1e-4, 3e-7), std::invalid_argument);
  EXPECT_THROW(makeLaw(0.1, 1e-4, 0.0), std::invalid_argument);
  EXPECT_THROW(makeLaw(std::numeric_limits<double>::quiet_NaN(), 1e-4, 3e-7), std::invalid_argument);
  try {
    makeLaw(0.1, 1e-4, 0.5e-7);
    FAIL() << "expected std::invalid_argument";
  } catch (const std::invalid_argument& ex) {
    EXPECT_NE(std::string(ex.what()).find("Gamma"), std::string::npos) << ex.what();
  }
  try {
    makeLaw(0.1, 0.0, 3e-7);
    FAIL() << "expected std::invalid_argument";
  } catch (const std::invalid_argument& ex) {
    EXPECT_NE(std::string(ex.what()).find("sigma0"), std::string::npos) << ex.what();
  }
  EXPECT_NO_THROW(makeLaw(0.1, 1e-4, 3e-7));
}

// The compact in-slice form (what the solver's kernel runs) against the general form, on random interfaces
// of one yz-slice (normal and arms without an x part) and random openings across every branch of the law,
// contact included: the force on B and the history agree bit for bit, and so do both wrenches.
TEST(Cohesive, SliceInterfaceFormEqualsTheGeneralForm) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0), u01(0.0, 1.0);
  for (int trial = 0; trial < 2000; ++trial) {
    const Vec3 xA(0.7, u(rng), u(rng)), xB(0.7, u(rng) + 1.2, u(rng));
    const Vec3 mid(0.7, 0.5 * (xA.y() + xB.y()) + 0.1 * u(rng), 0.5 * (xA.z() + xB.z()) + 0.1 * u(rng));
    const InterfaceGeometry g{makeFrame(xB - xA), mid - xA, mid - xB, 0.3 * u01(rng) + 0.01};
    const SliceInterface c = packInSlice(g);
    const double s = 1.5 * kLaw.deltaf();
    const Vec3 uA = randomVec(rng, s), thA = randomVec(rng, s), uB = randomVec(rng, s), thB = randomVec(rng, s);
    double lmGeneral = u01(rng) * kLaw.deltaf(), lmSlice = lmGeneral;
    const Vec3 fGeneral = computeInterfaceForceOnB(kLaw, g, uA, thA, uB, thB, lmGeneral);
    const Vec3 fSlice = computeInterfaceForceOnB(kLaw, c, uA, thA, uB, thB, lmSlice);
    ASSERT_EQ(lmSlice, lmGeneral) << "trial " << trial;
    for (int side = 0; side < 2; ++side) {
      const Wrench wg = wrenchOnSide(g, fGeneral, side), ws = wrenchOnSide(c, fSlice, side);
      for (int j = 0; j < 3; ++j) {
        ASSERT_EQ(ws.force[j], wg.force[j]) << "trial " << trial << " side " << side;
        ASSERT_EQ(ws.moment[j], wg.moment[j]) << "trial " << trial << " side " << side;
      }
    }
  }
}

TEST(Cohesive, PackInSliceRefusesAnInterfaceAcrossSlices) {
  const Vec3 xA(0, 0, 0), xB(0.1, 1, 0), mid(0.05, 0.5, 0.2);
  EXPECT_THROW(packInSlice(InterfaceGeometry{makeFrame(xB - xA), mid - xA, mid - xB, 0.1}), std::invalid_argument);
  const Vec3 yB(0, 1, 0), off(0.3, 0.5, 0);  // an arm with an x part
  EXPECT_THROW(packInSlice(InterfaceGeometry{makeFrame(yB - xA), off - xA, off - yB, 0.1}), std::invalid_argument);
}

// --- softening_over_delta0: the trapezoid's shape at fixed Gamma ---------------------------------------------

namespace {

// The law before the key, written out (delta1 = Gamma/sigma0, deltaf = delta1 + delta0, drop over delta0).
struct TodaysLaw {
  double k, sigma0, Gamma;
  double d0() const { return sigma0 / k; }
  double d1() const { return Gamma / sigma0; }
  double df() const { return d1() + d0(); }
  double envelope(double lambda) const {
    if (lambda <= d0()) return k * lambda;
    if (lambda <= d1()) return sigma0;
    if (lambda < df()) return sigma0 * (df() - lambda) / d0();
    return 0.0;
  }
  double secant(double lambdaMax) const {
    if (k * lambdaMax <= sigma0) return k;
    if (lambdaMax >= df()) return 0.0;
    return envelope(lambdaMax) / lambdaMax;
  }
};

bool sameBits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

}  // namespace

TEST(Cohesive, SofteningShapeKeepsAreaGamma) {
  // G = 3: allowed L/delta0 in (0, 5]; 1 = today's trapezoid, 5 = the triangle.
  for (double s : {0.05, 0.2, 0.5, 1.0, 2.5, 4.0, 5.0}) {
    const Law L = makeLaw(0.1, 1e-4, 3e-7, s);
    EXPECT_NEAR(L.deltaf() - L.delta1(), s * L.delta0(), kRoundoff * L.deltaf()) << s;
    EXPECT_GE(L.delta1(), L.delta0() * (1.0 - kRoundoff)) << s;
    const double area = 0.5 * L.sigma0 * L.delta0() + L.sigma0 * (L.delta1() - L.delta0()) +
                        0.5 * L.sigma0 * (L.deltaf() - L.delta1());
    EXPECT_NEAR(area, L.Gamma, kRoundoff * L.Gamma) << s;
    // The work of a monotonic opening (trapezoid rule, exact on each linear leg) is Gamma, in every mode.
    for (const Vec3& e : {Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0.6, -0.48, 0.64).normalized()}) {
      double lambdaMax = 0.0;
      EXPECT_NEAR(monotonicWork(L, e, lambdaMax), L.Gamma, kWorkTol * L.Gamma) << s;
      EXPECT_TRUE(isFailed(L, lambdaMax)) << s;
      EXPECT_NEAR(dissipatedEnergyDensity(L, lambdaMax), L.Gamma, 1e-12 * L.Gamma) << s;
    }
    // Continuity of the envelope at each kink.
    const double eps = 1e-9 * L.deltaf();
    const double slope = std::max(L.k, L.sigma0 / L.softeningLength());
    for (double kink : {L.delta0(), L.delta1(), L.deltaf()})
      EXPECT_NEAR(envelopeTraction(L, kink + eps), envelopeTraction(L, kink), 2.0 * slope * eps) << s << " " << kink;
  }
}

TEST(Cohesive, DefaultSofteningIsTodaysLawBitForBit) {
  // Several (k, sigma0, Gamma), among them the solver's defaults (Er/kd 10, delta0/d 0.1, G 3 and 8), and
  // lambdas across every branch and at the kinks: every quantity equal bit for bit.
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(0.0, 1.3);
  const std::vector<std::array<double, 3>> laws = {
      {0.1, 0.01, 3 * 1e-4 / 0.1}, {0.1, 0.01, 8 * 1e-4 / 0.1}, {0.1, 1e-4, 3e-7}, {0.05, 0.005, 7.3e-4},
      {1e-3, 2e-4, 4e-5 * 1.7}, {0.2, 0.03, 0.03 * 0.03 / 0.2}};
  for (const auto& [k, sigma0, Gamma] : laws) {
    const Law L = makeLaw(k, sigma0, Gamma);  // default softening_over_delta0 = 1
    const Law L1 = makeLaw(k, sigma0, Gamma, 1.0);
    const TodaysLaw T{k, sigma0, Gamma};
    EXPECT_TRUE(sameBits(L.delta0(), T.d0()) && sameBits(L1.delta0(), T.d0()));
    EXPECT_TRUE(sameBits(L.delta1(), T.d1()) && sameBits(L1.delta1(), T.d1())) << L.delta1() << " " << T.d1();
    EXPECT_TRUE(sameBits(L.deltaf(), T.df()) && sameBits(L1.deltaf(), T.df())) << L.deltaf() << " " << T.df();
    std::vector<double> lambdas = {0.0, T.d0(), T.d1(), T.df(), std::nextafter(T.d1(), 1.0), std::nextafter(T.df(), 0.0)};
    for (int i = 0; i < 2000; ++i) lambdas.push_back(u(rng) * T.df());
    for (double lambda : lambdas) {
      EXPECT_TRUE(sameBits(envelopeTraction(L1, lambda), T.envelope(lambda))) << lambda;
      EXPECT_TRUE(sameBits(secantStiffness(L1, lambda), T.secant(lambda))) << lambda;
      const Vec3 opening = lambda * Vec3(0.6, -0.48, 0.64).normalized();
      double hNew = 0.3 * lambda, hOld = 0.3 * lambda;
      const Vec3 tNew = computeTraction(L1, opening, hNew);
      // Today's computeTraction: S(lambdaMax) (<dn>_+, dt1, dt2) + (k min(dn, 0), 0, 0).
      hOld = std::max(hOld, effectiveSeparation(opening));
      const double S = T.secant(hOld);
      const Vec3 tOld(S * std::max(opening(0), 0.0) + k * std::min(opening(0), 0.0), S * opening(1), S * opening(2));
      for (int c = 0; c < 3; ++c) EXPECT_TRUE(sameBits(tNew(c), tOld(c))) << lambda;
      // the history too, except on the elastic track (below delta0, where it is not recorded)
      if (!sameBits(hNew, hOld)) EXPECT_TRUE(hOld < T.d0() && hNew == 0.3 * lambda) << lambda;
    }
  }
}

TEST(Cohesive, TriangleLimitHasNoPlateau) {
  // L/delta0 = 2G - 1: delta1 = delta0, peak sigma0 at delta0, linear to zero at deltaf = 2 Gamma/sigma0.
  for (double G : {1.0, 3.0, 8.0}) {
    const double k = 0.1, sigma0 = 0.01, Gamma = G * sigma0 * sigma0 / k;
    const Law L = makeLaw(k, sigma0, Gamma, 2.0 * G - 1.0);
    EXPECT_NEAR(L.delta1(), L.delta0(), kRoundoff * L.deltaf()) << G;
    EXPECT_NEAR(L.deltaf(), 2.0 * Gamma / sigma0, kRoundoff * L.deltaf()) << G;
    EXPECT_NEAR(envelopeTraction(L, L.delta0()), sigma0, kRoundoff * sigma0) << G;
    for (double f : {0.1, 0.5, 0.9}) {
      const double lambda = L.delta0() + f * (L.deltaf() - L.delta0());
      EXPECT_NEAR(envelopeTraction(L, lambda), sigma0 * (1.0 - f), 1e-10 * sigma0) << G << " " << f;
    }
    double lambdaMax = 0.0;
    EXPECT_NEAR(monotonicWork(L, Vec3(0, 0, 1), lambdaMax), Gamma, kWorkTol * Gamma) << G;
  }
  // G = 1: the only allowed shape is the triangle, L/delta0 = 1 (today's law at G = 1).
  EXPECT_NO_THROW(makeLaw(0.1, 0.01, 0.01 * 0.01 / 0.1, 1.0));
  EXPECT_THROW(makeLaw(0.1, 0.01, 0.01 * 0.01 / 0.1, 1.01), std::invalid_argument);
}

TEST(Cohesive, SofteningIsMonotone) {
  // Past delta0 the envelope never rises and the secant stiffness never rises, for every shape.
  for (double s : {0.05, 0.2, 1.0, 3.0, 5.0}) {
    const Law L = makeLaw(0.1, 1e-4, 3e-7, s);
    double prevT = envelopeTraction(L, L.delta0()), prevS = secantStiffness(L, L.delta0());
    for (int i = 1; i <= 4000; ++i) {
      const double lambda = L.delta0() + (1.2 * L.deltaf() - L.delta0()) * i / 4000.0;
      const double T = envelopeTraction(L, lambda), S = secantStiffness(L, lambda);
      EXPECT_LE(T, prevT) << s << " " << lambda;
      EXPECT_LE(S, prevS) << s << " " << lambda;
      EXPECT_GE(T, 0.0);
      prevT = T, prevS = S;
    }
    double prevW = 0.0;
    for (int i = 0; i <= 400; ++i) {
      const double w = dissipatedEnergyDensity(L, 1.2 * L.deltaf() * i / 400.0);
      EXPECT_GE(w, prevW) << s << " " << i;
      prevW = w;
    }
  }
}

TEST(Cohesive, MakeLawRejectsBadSoftening) {
  // G = 3: allowed (0, 5].
  for (double s : {0.0, -1.0, 5.01, 100.0, std::numeric_limits<double>::quiet_NaN()}) {
    try {
      makeLaw(0.1, 1e-4, 3e-7, s);
      ADD_FAILURE() << "expected std::invalid_argument for " << s;
    } catch (const std::invalid_argument& ex) {
      EXPECT_NE(std::string(ex.what()).find("softening_over_delta0"), std::string::npos) << ex.what();
    }
  }
  EXPECT_NO_THROW(makeLaw(0.1, 1e-4, 3e-7, 5.0));
  EXPECT_NO_THROW(makeLaw(0.1, 1e-4, 3e-7, 1e-6));
}

// The elastic track of computeTraction (no square root, lambdaMax not recorded while the law cannot depend
// on it) against the plain law written out here (lambdaMax = the largest lambda, always): along random paths
// that load, unload and reload across delta0 (and some that stay just below it, or hover at the track's bound),
// the traction is the same bit for bit at every point, and so is everything computed from lambdaMax (damage,
// dissipated and stored energy, inelastic, failed). lambdaMax itself differs only below delta0. With the
// symmetric trapezoid, the triangle and the steep drop.
TEST(Cohesive, ElasticTrackEqualsThePlainMaximum) {
  auto plainTraction = [](const Law& law, const Vec3& o, double& lm) {
    lm = std::max(lm, effectiveSeparation(o));
    const double S = secantStiffness(law, lm);
    const double dn = o(0);
    return Vec3(S * std::max(dn, 0.0) + law.k * std::min(dn, 0.0), S * o(1), S * o(2));
  };
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  int tracked = 0, recorded = 0, differing = 0;
  for (const Law& law : {kLaw, makeLaw(0.1, 1e-4, 3e-7, 5.0), makeLaw(0.1, 1e-4, 3e-7, 0.2)}) {
    const double d0 = law.delta0();
    for (int path = 0; path < 300; ++path) {
      // peak amplitude: 0.5-2.5 delta0, or within a few 1e-7 of the track's bound for a third of the paths
      const double peak = path % 3 == 0 ? d0 * std::sqrt(kElasticTrack) * (1 + 3e-7 * unit(rng)) : d0 * (1.5 + unit(rng));
      const Vec3 dir = Vec3(unit(rng), unit(rng), unit(rng)).normalized();
      double lmTrack = 0, lmPlain = 0;
      for (int i = 0; i <= 200; ++i) {
        const double s = std::abs(std::sin(0.05 * i * (1 + path % 7)));  // loads, unloads, reloads
        const Vec3 o = peak * s * dir + 0.01 * d0 * Vec3(unit(rng), unit(rng), unit(rng));
        const double before = lmTrack;
        const Vec3 tTrack = computeTraction(law, o, lmTrack), tPlain = plainTraction(law, o, lmPlain);
        tracked += lmTrack == before && effectiveSeparation(o) > before;
        recorded += lmTrack > before;
        for (int j = 0; j < 3; ++j) ASSERT_EQ(tTrack[j], tPlain[j]) << "path " << path << " point " << i;
        ASSERT_EQ(damage(law, lmTrack), damage(law, lmPlain));
        ASSERT_EQ(dissipatedEnergyDensity(law, lmTrack), dissipatedEnergyDensity(law, lmPlain));
        ASSERT_EQ(storedEnergyDensity(law, o, lmTrack), storedEnergyDensity(law, o, lmPlain));
        ASSERT_EQ(isInelastic(law, lmTrack), isInelastic(law, lmPlain));
        ASSERT_EQ(isFailed(law, lmTrack), isFailed(law, lmPlain));
        if (lmTrack != lmPlain) {
          ASSERT_LT(lmPlain, d0);
          ++differing;
        }
      }
    }
  }
  EXPECT_GT(tracked, 1000) << "the track is taken";
  EXPECT_GT(recorded, 1000) << "and left";
  EXPECT_GT(differing, 1000) << "so lambdaMax does differ below delta0";
}

// --- shear_strength_ratio: the mixed-mode law, lambda = sqrt(<dn>_+^2 + (dt1^2 + dt2^2)/beta^2) ------------------

namespace {

// The peak traction magnitude and the work along a monotonic opening s * e from 0 to 1.2 sFail, e a unit
// direction, sFail the opening size at which lambda = deltaf; each leg ends at a kink of the envelope (lambda =
// delta0, delta1, deltaf: s = lambda / lambda(e)), and the traction is linear in s on each, so the trapezoid rule
// is exact. Also the dissipation booked along it, as the solver books it (dissipationIncrement at each point).
struct MonotonicPath { double peak, work, booked, lambdaMax; };

MonotonicPath monotonicPath(const Law& law, const Vec3& e, int n = 400) {
  const double perUnit = effectiveSeparation(law, e);  // lambda of the unit opening e
  const std::vector<double> breaks = {0.0, law.delta0() / perUnit, law.delta1() / perUnit, law.deltaf() / perUnit,
                                      1.2 * law.deltaf() / perUnit};
  MonotonicPath r{0.0, 0.0, 0.0, 0.0};
  Vec3 tPrev = computeTraction(law, Vec3::Zero(), r.lambdaMax);
  for (std::size_t b = 1; b < breaks.size(); ++b)
    for (int i = 1; i <= n; ++i) {
      const double s0 = breaks[b - 1] + (breaks[b] - breaks[b - 1]) * (i - 1) / n;
      const double s1 = breaks[b - 1] + (breaks[b] - breaks[b - 1]) * i / n;
      const double before = r.lambdaMax;
      const Vec3 t = computeTraction(law, s1 * e, r.lambdaMax);
      r.work += 0.5 * (tPrev + t).dot((s1 - s0) * e);
      r.booked += dissipationIncrement(law, s1 * e, before, r.lambdaMax);
      r.peak = std::max(r.peak, t.norm());
      tPrev = t;
    }
  return r;
}

}  // namespace

// Pure shear (along t1, t2 and between them): elastic stiffness k, strength beta sigma0, fracture energy
// beta^2 Gamma, failed at the end; and the booked dissipation is the work done (everything dissipated: the
// traction is 0 at the end). Pure normal opening keeps sigma0 and Gamma whatever beta.
TEST(Cohesive, ShearStrengthRatioSetsShearStrengthAndToughness) {
  for (double beta : {0.3, 0.5, 1.0, 2.0, 3.5}) {
    const Law law = makeLaw(0.1, 1e-4, 3e-7, 1.0, beta);
    EXPECT_EQ(law.shearStrengthRatio, beta);
    for (const Vec3& e : {Vec3(0, 1, 0), Vec3(0, 0, -1), Vec3(0, 0.6, 0.8)}) {
      double lm = 0.0;
      const Vec3 tSmall = computeTraction(law, 1e-3 * law.delta0() * e, lm);
      EXPECT_NEAR((tSmall - law.k * 1e-3 * law.delta0() * e).norm(), 0.0, kRoundoff * law.k * law.delta0()) << beta;
      const MonotonicPath p = monotonicPath(law, e);
      EXPECT_NEAR(p.peak, beta * law.sigma0, kRoundoff * beta * law.sigma0) << "beta " << beta;
      EXPECT_NEAR(p.work, beta * beta * law.Gamma, kWorkTol * beta * beta * law.Gamma) << "beta " << beta;
      EXPECT_NEAR(p.booked, p.work, kWorkTol * p.work) << "beta " << beta;
      EXPECT_TRUE(isFailed(law, p.lambdaMax)) << beta;
      EXPECT_NEAR(modeFactor(law, e), beta * beta, kRoundoff * beta * beta);
    }
    const MonotonicPath normal = monotonicPath(law, Vec3(1, 0, 0));
    EXPECT_NEAR(normal.peak, law.sigma0, kRoundoff * law.sigma0) << beta;
    EXPECT_NEAR(normal.work, law.Gamma, kWorkTol * law.Gamma) << beta;
    EXPECT_NEAR(normal.booked, law.Gamma, kWorkTol * law.Gamma) << beta;
    EXPECT_NEAR(dissipatedEnergyDensity(law, normal.lambdaMax), law.Gamma, kRoundoff * law.Gamma) << beta;
    // a mixed radial opening: the work is the mode factor times Gamma, and so is the booked dissipation
    const Vec3 mixed = Vec3(0.6, -0.48, 0.64).normalized();
    const double lambdaMixed = effectiveSeparation(law, mixed), m = mixed.squaredNorm() / (lambdaMixed * lambdaMixed);
    EXPECT_NEAR(modeFactor(law, mixed), m, kRoundoff * m) << beta;
    const MonotonicPath p = monotonicPath(law, mixed);
    EXPECT_NEAR(p.work, m * law.Gamma, kWorkTol * m * law.Gamma) << beta;
    EXPECT_NEAR(p.booked, m * law.Gamma, kWorkTol * m * law.Gamma) << beta;
  }
}

// The shear toughness, derived: in pure shear lambda = |dt|/beta, so |t| = S(lambda) |dt| = beta T(lambda) and
// int |t| d|dt| = int beta T(lambda) beta dlambda = beta^2 Gamma. Integrated here with the envelope alone (no
// computeTraction), as a check of the derivation that the test above checks on the law.
TEST(Cohesive, ShearToughnessIsBetaSquaredGammaByTheEnvelope) {
  for (double beta : {0.5, 2.0}) {
    const Law law = makeLaw(0.1, 1e-4, 3e-7, 2.0, beta);
    const int n = 200000;
    const double dtEnd = 1.1 * beta * law.deltaf();
    double work = 0.0;
    for (int i = 0; i < n; ++i) {
      const double dt = (i + 0.5) * dtEnd / n;  // midpoint rule
      work += beta * envelopeTraction(law, dt / beta) * dtEnd / n;
    }
    EXPECT_NEAR(work, beta * beta * law.Gamma, 1e-6 * beta * beta * law.Gamma) << beta;
  }
}

// beta = 1 is the law before the key, bit for bit, on random openings (both signs of dn, every branch) and
// histories: the separation, the traction (and the history it leaves), the stored energy, the mode factor and
// the dissipation increment, against the formulas written out.
TEST(Cohesive, ShearStrengthRatioOneIsTodaysLawBitForBit) {
  std::mt19937_64 rng(23);
  std::uniform_real_distribution<double> u(-1.0, 1.0), pos(0.0, 1.0);
  for (const auto& [k, sigma0, Gamma] : std::vector<std::array<double, 3>>{
           {0.1, 0.01, 3 * 1e-4 / 0.1}, {0.1, 0.01, 8 * 1e-4 / 0.1}, {0.1, 1e-4, 3e-7}, {0.05, 0.005, 7.3e-4}}) {
    const Law L = makeLaw(k, sigma0, Gamma, 1.0, 1.0);
    const TodaysLaw T{k, sigma0, Gamma};
    EXPECT_TRUE(L.isotropic());
    for (int i = 0; i < 20000; ++i) {
      const Vec3 o = 1.3 * T.df() * Vec3(u(rng), u(rng), u(rng));
      const double lambdaOld = std::sqrt(std::max(o(0), 0.0) * std::max(o(0), 0.0) + o(1) * o(1) + o(2) * o(2));
      ASSERT_TRUE(sameBits(effectiveSeparation(L, o), lambdaOld)) << i;
      ASSERT_TRUE(sameBits(effectiveSeparation(L, o), effectiveSeparation(o))) << i;
      const double h0 = pos(rng) * 1.2 * T.df();
      double hNew = h0;
      const Vec3 tNew = computeTraction(L, o, hNew);
      const double hOld = std::max(h0, lambdaOld), S = T.secant(hOld);
      const Vec3 tOld(S * std::max(o(0), 0.0) + k * std::min(o(0), 0.0), S * o(1), S * o(2));
      for (int c = 0; c < 3; ++c) ASSERT_TRUE(sameBits(tNew(c), tOld(c))) << i;
      if (!sameBits(hNew, hOld)) ASSERT_TRUE(hOld < T.d0() && hNew == h0) << i;
      const double dnNeg = std::max(-o(0), 0.0);
      const double storedOld = 0.5 * T.secant(std::max(h0, lambdaOld)) * lambdaOld * lambdaOld + 0.5 * k * dnNeg * dnNeg;
      ASSERT_TRUE(sameBits(storedEnergyDensity(L, o, h0), storedOld)) << i;
      ASSERT_EQ(modeFactor(L, o), 1.0);
      const double h1 = h0 + pos(rng) * T.df();
      ASSERT_TRUE(sameBits(dissipationIncrement(L, o, h0, h1),
                           dissipatedEnergyDensity(L, h1) - dissipatedEnergyDensity(L, h0)) ||
                  dissipatedEnergyDensity(L, h1) == dissipatedEnergyDensity(L, h0))
          << i;
    }
  }
}

// The elastic track with beta != 1: its bound is on the mixed-mode lambda, so along random paths across delta0
// the traction and everything computed from lambdaMax equal those of the plain maximum of lambda, bit for bit
// (as ElasticTrackEqualsThePlainMaximum at beta = 1).
TEST(Cohesive, ElasticTrackHoldsForTheMixedModeLambda) {
  std::mt19937_64 rng(31);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  int tracked = 0, recorded = 0;
  for (double beta : {0.4, 2.5}) {
    const Law law = makeLaw(0.1, 1e-4, 3e-7, 1.0, beta);
    const double d0 = law.delta0();
    for (int path = 0; path < 200; ++path) {
      const Vec3 dir = Vec3(unit(rng), unit(rng), unit(rng)).normalized();
      const double peak = d0 * (path % 3 == 0 ? std::sqrt(kElasticTrack) * (1 + 3e-7 * unit(rng)) : 1.5 + unit(rng)) /
                          effectiveSeparation(law, dir);
      double lmTrack = 0, lmPlain = 0;
      for (int i = 0; i <= 200; ++i) {
        const double s = std::abs(std::sin(0.05 * i * (1 + path % 7)));
        const Vec3 o = peak * s * dir + 0.01 * d0 * Vec3(unit(rng), unit(rng), unit(rng));
        const double before = lmTrack;
        const Vec3 tTrack = computeTraction(law, o, lmTrack);
        lmPlain = std::max(lmPlain, effectiveSeparation(law, o));
        const double S = secantStiffness(law, lmPlain);
        const Vec3 tPlain(S * std::max(o(0), 0.0) + law.k * std::min(o(0), 0.0), S * o(1), S * o(2));
        tracked += lmTrack == before && effectiveSeparation(law, o) > before;
        recorded += lmTrack > before;
        for (int j = 0; j < 3; ++j) ASSERT_EQ(tTrack[j], tPlain[j]) << "beta " << beta << " path " << path;
        ASSERT_EQ(damage(law, lmTrack), damage(law, lmPlain));
        ASSERT_EQ(dissipatedEnergyDensity(law, lmTrack), dissipatedEnergyDensity(law, lmPlain));
        ASSERT_EQ(storedEnergyDensity(law, o, lmTrack), storedEnergyDensity(law, o, lmPlain));
        ASSERT_EQ(isInelastic(law, lmTrack), isInelastic(law, lmPlain));
        ASSERT_EQ(isFailed(law, lmTrack), isFailed(law, lmPlain));
        if (lmTrack != lmPlain) ASSERT_LT(lmPlain, d0);
      }
    }
  }
  EXPECT_GT(tracked, 500) << "the track is taken";
  EXPECT_GT(recorded, 500) << "and left";
}

// The energy account along a path that changes mode (shear past the peak, unloading, normal opening with some
// shear, contact, then shear again to failure), in small steps: the work done equals the stored energy plus the
// dissipation booked step by step (dissipationIncrement at the step's end), within the steps' O(h) error.
// lambdaMax alone does not give it: the normal-mode dissipatedEnergyDensity misses the shear part.
TEST(Cohesive, MixedModeWorkIsStoredPlusBookedDissipation) {
  for (double beta : {0.5, 2.0}) {
    const Law law = makeLaw(0.1, 1e-4, 3e-7, 1.0, beta);
    const double d0 = law.delta0(), b = beta;
    const std::vector<Vec3> corners = {Vec3::Zero(), Vec3(0, 1.6 * b * d0, 0), Vec3(0, 0.2 * b * d0, 0),
                                       Vec3(2.2 * d0, 0.5 * b * d0, 0.3 * b * d0), Vec3(-0.5 * d0, 0, 0),
                                       Vec3(0.2 * d0, 0, 1.3 * b * law.deltaf()), Vec3(0.5 * d0, 0, 0)};
    double lm = 0.0, work = 0.0, booked = 0.0, worst = 0.0;
    Vec3 tPrev = computeTraction(law, corners[0], lm);
    for (std::size_t c = 1; c < corners.size(); ++c) {
      const int n = 20000;
      for (int i = 1; i <= n; ++i) {
        const Vec3 a = corners[c - 1] + (corners[c] - corners[c - 1]) * (double(i - 1) / n);
        const Vec3 o = corners[c - 1] + (corners[c] - corners[c - 1]) * (double(i) / n);
        const double before = lm;
        const Vec3 t = computeTraction(law, o, lm);
        work += 0.5 * (tPrev + t).dot(o - a);
        booked += dissipationIncrement(law, o, before, lm);
        tPrev = t;
        worst = std::max(worst, std::abs(work - storedEnergyDensity(law, o, lm) - booked));
      }
      if (c == 3)  // after the mixed leg: the normal-mode account alone would be off by far more than the error
        EXPECT_GT(std::abs(work - storedEnergyDensity(law, corners[c], lm) - dissipatedEnergyDensity(law, lm)),
                  0.05 * law.Gamma) << beta;
    }
    EXPECT_TRUE(isFailed(law, lm)) << beta;
    EXPECT_LT(worst, 2e-4 * law.Gamma) << "beta " << beta << ": work " << work << " booked " << booked;
    EXPECT_GT(booked, std::min(1.0, beta * beta) * law.Gamma) << beta;
  }
}

TEST(Cohesive, MakeLawRejectsBadShearStrengthRatio) {
  for (double beta : {0.0, -1.0, 10.5, std::numeric_limits<double>::quiet_NaN(),
                      std::numeric_limits<double>::infinity()}) {
    try {
      makeLaw(0.1, 1e-4, 3e-7, 1.0, beta);
      ADD_FAILURE() << "expected std::invalid_argument for " << beta;
    } catch (const std::invalid_argument& ex) {
      EXPECT_NE(std::string(ex.what()).find("shear_strength_ratio"), std::string::npos) << ex.what();
    }
  }
  EXPECT_NO_THROW(makeLaw(0.1, 1e-4, 3e-7, 1.0, 10.0));
  EXPECT_NO_THROW(makeLaw(0.1, 1e-4, 3e-7, 1.0, 1e-3));
}
