// The pre-crack tip (docs/model.md, Geometry): the quarter-point rule that no round-off can flip, the readings
// of the crisscross at the tip (crisscross_at_tip, crisscross_phase), and the crack advance measured on any
// path of the cluster joined to the pre-crack (measurements.cpp).
#include <gtest/gtest.h>

#include <cmath>
#include <set>
#include <tuple>

#include "data/state.hpp"
#include "geometry/geometry.hpp"
#include "kernels/measurements.hpp"
#include "laws/cohesive_law.hpp"

#include "specimen.hpp"

using namespace enamel;

namespace {

// What the pre-crack removed, as sets of (ply, rod index j, slice): rod elements by their first slice,
// interfaces by both rods. Rod numbers are not used: they could shift if a rod's end moved.
struct RemovedSet {
  std::set<std::tuple<int, int, int>> beams;
  std::set<std::tuple<int, int, int, int, int>> interfaces;
  bool operator==(const RemovedSet& o) const { return beams == o.beams && interfaces == o.interfaces; }
};

RemovedSet removedSet(const Model& m) {
  RemovedSet r;
  for (std::size_t c = 0; c < m.precrackBeamRod.size(); ++c) {
    const int rod = m.precrackBeamRod[c];
    r.beams.insert({m.rodPly[rod], m.rodIndex[rod], m.precrackBeamSlice[c]});
  }
  for (std::size_t c = 0; c < m.precrackIfaceRods.size(); ++c) {
    const auto [a, b] = m.precrackIfaceRods[c];
    r.interfaces.insert({m.rodPly[a], m.rodIndex[a], m.rodPly[b], m.rodIndex[b], m.precrackIfaceSlice[c]});
  }
  return r;
}

int rodOf(const Model& m, int ply, int j) {
  for (int r = 0; r < m.numRods(); ++r)
    if (m.rodPly[r] == ply && m.rodIndex[r] == j) return r;
  return -1;
}

// The intact rod element of rod `rod` starting in slice k, or -1.
int beamAt(const Model& m, int rod, int k) {
  for (int e = 0; e < m.numBeams(); ++e)
    if (m.beamRod[e] == rod && m.nodeSlice[m.beamNodes[e][0]] == k) return e;
  return -1;
}

bool precrackCutBeam(const Model& m, int rod, int k) {
  for (std::size_t c = 0; c < m.precrackBeamRod.size(); ++c)
    if (m.precrackBeamRod[c] == rod && m.precrackBeamSlice[c] == k) return true;
  return false;
}

}  // namespace

// The slice lattice puts a0 = w_s/2 exactly on a slice (ci: 16 d in 53 slices of 0.3019 d would not, but 80 d
// in 267 does at even counts): a hair of a0 or h_e must not change what the pre-crack removes.
TEST(Precrack, RemovedSetDoesNotMoveWithA0OrHeByAHair) {
  const double hair = 1e-9;
  for (auto [w, h] : {std::pair{16.0, 8.0}, std::pair{80.0, 80.0}})
    for (double theta : {0.0, 15.0, 30.0}) {
      const GeometryParams base = specimen(theta, w, h);
      const Model m0 = buildCrossply(base);
      const RemovedSet r0 = removedSet(m0);
      ASSERT_FALSE(r0.interfaces.empty());
      if (theta > 0) ASSERT_FALSE(r0.beams.empty());
      const int slices = m0.numSlices - 1;
      for (double sign : {-1.0, 1.0}) {
        GeometryParams a = base;  // a0 by a hair
        a.a0 += sign * hair;
        GeometryParams e = base;  // h_e by a hair (w_s by (N-1) hairs), a0 kept
        e.w_s += sign * hair * slices;
        GeometryParams ws = base;  // w_s by a hair with a0 = w_s/2 (a0_over_ws = 0.5 and w_s_over_d moved)
        ws.w_s += sign * hair;
        ws.a0 = 0.5 * ws.w_s;
        for (const GeometryParams& p : {a, e, ws}) {
          const Model m = buildCrossply(p);
          EXPECT_EQ(m.precrackLastSlice, m0.precrackLastSlice) << "w " << w << " theta " << theta;
          EXPECT_NEAR(m.a0Eff, m0.a0Eff, 1e-6);
          EXPECT_TRUE(removedSet(m) == r0)
              << "w " << w << " theta " << theta << ": " << m.precrackBeams << " rod elements, "
              << m.precrackInterfaces << " interfaces removed against " << m0.precrackBeams << ", "
              << m0.precrackInterfaces << " (a0 " << p.a0 << ", w_s " << p.w_s << ")";
        }
      }
    }
}

TEST(Precrack, TipIsTheQuarterPointAfterTheLastCutSlice) {
  EXPECT_EQ(precrackTip(3.0, 0.3).lastSlice, 10);  // 3/0.3 is 10 within round-off: the tolerance makes it 10
  EXPECT_NEAR(precrackTip(3.0, 0.3).a0Eff, 3.075, 1e-12);
  EXPECT_EQ(precrackTip(3.0 - 1e-9, 0.3).lastSlice, 10);
  EXPECT_EQ(precrackTip(3.0 - 1e-3, 0.3).lastSlice, 9);
  EXPECT_EQ(precrackTip(3.1, 0.3).lastSlice, 10);
  for (double theta : {0.0, 30.0}) {
    const Model m = buildCrossply(specimen(theta, 16, 8));
    const int K = m.precrackLastSlice;
    EXPECT_NEAR(m.a0Eff, (K + 0.25) * m.h_e, 1e-12);
    EXPECT_LE(std::abs(m.a0Eff - m.a0), 0.75 * m.h_e);
    std::set<int> cutSlices(m.precrackIfaceSlice.begin(), m.precrackIfaceSlice.end());
    EXPECT_EQ(*cutSlices.rbegin(), K);
    EXPECT_EQ(static_cast<int>(cutSlices.size()), K + 1);  // every slice 0..K cut
    for (int k : m.precrackBeamSlice) EXPECT_LT(k, K);    // elements [k, k+1] with k + 1 <= K
    // What is left crosses the mid-plane only ahead of the tip.
    for (int i = 0; i < m.numInterfaces(); ++i) {
      if (m.ifaceSlice[i] > K) continue;
      EXPECT_EQ(belowCrackPlane(m, m.X[m.ifaceNodes[i][0]].y()), belowCrackPlane(m, m.X[m.ifaceNodes[i][1]].y()));
    }
    for (int e = 0; e < m.numBeams(); ++e) {
      if (m.nodeSlice[m.beamNodes[e][1]] > K) continue;
      EXPECT_EQ(belowCrackPlane(m, m.X[m.beamNodes[e][0]].y()), belowCrackPlane(m, m.X[m.beamNodes[e][1]].y()));
    }
  }
}

// (a) intact: the crisscross at a0_eff, inside element [K, K+1], both rods' elements there kept; (b) cut: at
// a0_eff - h_e/2, inside [K-1, K], both cut, and the next crisscross d/sin(theta) ahead intact; (c) the phase
// shifts the lattice by its fraction of d/sin(theta) from the reading's origin.
TEST(Precrack, CrisscrossAtTipIntactOrCut) {
  for (double theta : {15.0, 30.0}) {
    GeometryParams p = specimen(theta, 30, 10);
    const Model intact = buildCrossply(p);
    p.crisscrossCutAtTip = true;
    const Model cut = buildCrossply(p);
    const int K = intact.precrackLastSlice;
    ASSERT_EQ(cut.precrackLastSlice, K);
    EXPECT_NEAR(intact.xCrisscross, intact.a0Eff, 1e-12);
    EXPECT_NEAR(cut.xCrisscross, cut.a0Eff - 0.5 * cut.h_e, 1e-12);
    const double spacing = 1.0 / std::sin(theta * M_PI / 180);
    const int kAhead = static_cast<int>(std::floor((cut.xCrisscross + spacing) / cut.h_e));
    for (int ply : {0, 1}) {
      // rod 0 of each ply crosses the mid-plane at xCrisscross (rodCentreY)
      const int ri = rodOf(intact, ply, 0), rc = rodOf(cut, ply, 0);
      ASSERT_GE(ri, 0);
      ASSERT_GE(rc, 0);
      EXPECT_GE(beamAt(intact, ri, K), 0) << "theta " << theta << " ply " << ply;
      EXPECT_FALSE(precrackCutBeam(intact, ri, K));
      EXPECT_FALSE(precrackCutBeam(intact, ri, K - 1));
      EXPECT_TRUE(precrackCutBeam(cut, rc, K - 1)) << "theta " << theta << " ply " << ply;
      EXPECT_EQ(beamAt(cut, rc, K - 1), -1);
      // the nearest crisscross ahead: ply-1 rod -1 and ply-2 rod 1 at xCrisscross + d/sin(theta), kept
      const int ahead = rodOf(cut, ply, ply == 0 ? -1 : 1);
      ASSERT_GE(ahead, 0);
      EXPECT_GE(beamAt(cut, ahead, kAhead), 0);
      EXPECT_NEAR(rodCentreY(cut, ply, ply == 0 ? -1 : 1, cut.xCrisscross + spacing), cut.yCrack, 1e-9);
    }
    // The cut reading removes the crisscross's two rod elements that the intact one keeps.
    EXPECT_EQ(cut.precrackBeams - intact.precrackBeams, 2) << "theta " << theta;
    p.crisscross_phase = 0.4;
    const Model phased = buildCrossply(p);
    EXPECT_NEAR(phased.xCrisscross, cut.xCrisscross + 0.4 * spacing, 1e-12);
    p.crisscrossCutAtTip = false;
    EXPECT_NEAR(buildCrossply(p).xCrisscross, intact.a0Eff + 0.4 * spacing, 1e-12);
  }
}

namespace {

// A crack prescribed on a model: interfaces failed and rod elements deleted.
struct CrackFixture {
  Model m;
  cohesive::Law law;
  State s;
  explicit CrackFixture(double theta) : m(buildCrossply(specimen(theta, 30, 16))) {
    law = cohesive::makeLaw(0.1, 0.01, 0.01 * 0.01 / 0.1 * 10, 1, 1);
    s.lambdaMax.assign(m.numInterfaces(), 0.0);
    s.beamBroken.assign(m.numBeams(), 0);
  }
  double failed() const { return 10 * law.deltaf(); }
  // Fail the in-ply interface of slice k between rods (ply, j) and (ply, j + 1): a crack along the band
  // between two rods of one ply.
  int failBand(int k, int ply, int j) {
    const int a = rodOf(m, ply, j), b = rodOf(m, ply, j + 1);
    int n = 0;
    for (int i = 0; i < m.numInterfaces(); ++i) {
      if (m.ifaceSlice[i] != k) continue;
      const int ra = m.nodeRod[m.ifaceNodes[i][0]], rb = m.nodeRod[m.ifaceNodes[i][1]];
      if ((ra == a && rb == b) || (ra == b && rb == a)) { s.lambdaMax[i] = failed(); ++n; }
    }
    return n;
  }
  // Fail every interface of slice k that crosses the mid-plane.
  int failMidPlane(int k) {
    int n = 0;
    for (int i = 0; i < m.numInterfaces(); ++i)
      if (m.ifaceSlice[i] == k &&
          belowCrackPlane(m, m.X[m.ifaceNodes[i][0]].y()) != belowCrackPlane(m, m.X[m.ifaceNodes[i][1]].y())) {
        s.lambdaMax[i] = failed();
        ++n;
      }
    return n;
  }
  double advance() const { return measureCrackAdvance(m, law, s); }
};

}  // namespace

TEST(CrackAdvance, NothingFailedIsZeroAndThePrecrackAloneIsZero) {
  CrackFixture f(30);
  EXPECT_EQ(f.advance(), 0.0);
}

// A crack kinked off the mid-plane along +theta (the band between ply-1 rods -1 and 0, which rises at
// +theta ahead of the crisscross) or -theta (between ply-2 rods -1 and 0, which falls): Delta_a is its projected
// length, although its far end lies several d off the mid-plane.
TEST(CrackAdvance, KinkedCrackOffTheMidPlaneCountsItsProjectedLength) {
  for (int ply : {0, 1}) {
    CrackFixture f(30);
    const int K = f.m.precrackLastSlice, n = 20;
    for (int k = K + 1; k <= K + n; ++k) ASSERT_GT(f.failBand(k, ply, -1), 0) << "slice " << k;
    EXPECT_NEAR(f.advance(), (K + n) * f.m.h_e - f.m.a0Eff, 1e-12) << "ply " << ply;
    // its far end is off the mid-plane: rod 0 there at (n h_e - h_e/4) tan(theta) = 3.4 d from it
    const double yFar = rodCentreY(f.m, ply, 0, (K + n) * f.m.h_e);
    EXPECT_GT(std::abs(yFar - f.m.yCrack), 2.5);
    // and a rod element deleted where the kinked crack ends extends it by half a slice
    const int rod = rodOf(f.m, ply, 0), e = beamAt(f.m, rod, K + n);
    ASSERT_GE(e, 0);
    f.s.beamBroken[e] = 1;
    EXPECT_NEAR(f.advance(), (K + n + 0.5) * f.m.h_e - f.m.a0Eff, 1e-12);
  }
}

// A daughter crack ahead of the tip (a mid-plane stretch of failed interfaces with a gap before it) is not
// counted until a linking set of failures joins it to the pre-crack; then all of it counts.
TEST(CrackAdvance, DaughterCrackCountsOnlyOnceJoined) {
  for (double theta : {0.0, 30.0}) {
    CrackFixture f(theta);
    const int K = f.m.precrackLastSlice;
    for (int k = K + 10; k <= K + 16; ++k) ASSERT_GT(f.failMidPlane(k), 0);
    EXPECT_EQ(f.advance(), 0.0) << "theta " << theta;
    for (int k = K + 1; k <= K + 5; ++k) f.failMidPlane(k);
    EXPECT_NEAR(f.advance(), (K + 5) * f.m.h_e - f.m.a0Eff, 1e-12) << "theta " << theta;
    for (int k = K + 6; k <= K + 7; ++k) f.failMidPlane(k);  // a gap of two slices is left: still apart
    EXPECT_NEAR(f.advance(), (K + 7) * f.m.h_e - f.m.a0Eff, 1e-12);
    f.failMidPlane(K + 8);  // one slice short: slices K+8 and K+10 touch no rod in adjacent slices
    EXPECT_NEAR(f.advance(), (K + 8) * f.m.h_e - f.m.a0Eff, 1e-12);
    f.failMidPlane(K + 9);  // joined
    EXPECT_NEAR(f.advance(), (K + 16) * f.m.h_e - f.m.a0Eff, 1e-12) << "theta " << theta;
  }
}

// The cluster's kinks: failed interfaces of the crack joining two rods on one side of the crack plane. A straight
// crack across the plane has none; a crack kinked along the rods has one per slice of the kink in the band (the
// bands between ply-1 rods -1 and 0 cross the plane at the crisscross, so only those past it count); a kink that is
// not joined to the pre-crack counts nothing.
TEST(CrackAdvance, KinksAreTheClustersFailedInterfacesOffThePlane) {
  CrackFixture f(30);
  const int K = f.m.precrackLastSlice;
  EXPECT_EQ(measureCrackCluster(f.m, f.law, f.s).offPlaneInterfaces, 0);
  for (int k = K + 1; k <= K + 4; ++k) f.failMidPlane(k);
  CrackCluster c = measureCrackCluster(f.m, f.law, f.s);
  EXPECT_EQ(c.offPlaneInterfaces, 0);
  EXPECT_NEAR(c.advance, f.advance(), 0);
  CrackFixture g(30);
  int offPlane = 0;
  for (int k = K + 1; k <= K + 20; ++k) {
    g.failBand(k, 0, -1);
    const int a = rodOf(g.m, 0, -1);
    for (int i = 0; i < g.m.numInterfaces(); ++i)
      if (g.m.ifaceSlice[i] == k && g.s.lambdaMax[i] > 0 && (g.m.nodeRod[g.m.ifaceNodes[i][0]] == a ||
                                                             g.m.nodeRod[g.m.ifaceNodes[i][1]] == a))
        offPlane += belowCrackPlane(g.m, g.m.X[g.m.ifaceNodes[i][0]].y()) ==
                    belowCrackPlane(g.m, g.m.X[g.m.ifaceNodes[i][1]].y());
  }
  ASSERT_GT(offPlane, 10);
  EXPECT_EQ(measureCrackCluster(g.m, g.law, g.s).offPlaneInterfaces, offPlane);
  CrackFixture apart(30);  // the same kink 10 slices ahead, with nothing joining it
  for (int k = K + 10; k <= K + 20; ++k) apart.failBand(k, 0, -1);
  EXPECT_EQ(measureCrackCluster(apart.m, apart.law, apart.s).offPlaneInterfaces, 0);
}
