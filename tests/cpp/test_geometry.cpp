// Crossply geometry (docs/model.md): Voronoi connectivity, edge lengths, crisscross spacing, periodic
// wrap, pre-crack and hand counts.
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <set>

#include "geometry/geometry.hpp"

using namespace enamel;

namespace {
constexpr double kGeomTol = 1e-9;  // exact geometry, only round-off

GeometryParams smallParams(double thetaDeg, double w = 6, double h = 4) {
  GeometryParams p;
  p.theta_deg = thetaDeg;
  p.w_s = w;
  p.h_s = h;
  p.a0 = w / 2;
  p.h_e = 0.3;
  return p;
}

// Interfaces per node in one slice, ignoring the pre-crack (build with a0 at the far edge region).
std::map<int, int> neighbourCount(const Model& m, int slice) {
  std::map<int, int> count;
  for (int i = 0; i < m.numInterfaces(); ++i) {
    if (m.ifaceSlice[i] != slice) continue;
    ++count[m.ifaceNodes[i][0]];
    ++count[m.ifaceNodes[i][1]];
  }
  return count;
}
}  // namespace

TEST(Geometry, Theta0InteriorRodsHaveSixNeighboursWithEdgeDOverSqrt3) {
  const Model m = buildCrossply(smallParams(0, 6, 8));
  const int slice = m.numSlices - 2;  // ahead of the pre-crack: nothing removed here
  const auto count = neighbourCount(m, slice);
  int interior = 0;
  for (auto [node, n] : count) {
    const double y = m.X[node].y();
    if (y > 1.0 && y < m.h_s - 1.0) {  // more than one spacing from the top and bottom faces
      EXPECT_EQ(n, 6) << "node " << node << " at y = " << y;
      ++interior;
    }
  }
  EXPECT_GT(interior, 8);
  for (int i = 0; i < m.numInterfaces(); ++i) {
    const double yA = m.X[m.ifaceNodes[i][0]].y(), yB = m.X[m.ifaceNodes[i][1]].y();
    if (std::min(yA, yB) > 1.0 && std::max(yA, yB) < m.h_s - 1.0) {
      EXPECT_NEAR(m.ifaceEdgeLength[i], 1.0 / std::sqrt(3.0), kGeomTol);
    }
    // The rods joined by an interface are one spacing apart (hexagonal packing).
    const auto& g = m.ifaceGeom[i];
    EXPECT_NEAR((g.armA - g.armB).norm(), 1.0, kGeomTol);
  }
}

TEST(Geometry, VoronoiEdgesCloseEachCellPerimeterAndTileTheStrip) {
  for (double theta : {0.0, 15.0, 30.0, 45.0}) {
    const Model m = buildCrossply(smallParams(theta, 6, 6));
    for (int k : {0, m.numSlices / 3, m.numSlices - 1}) {
      std::vector<Vec2> pts;
      for (int n = 0; n < m.numNodes(); ++n)
        if (m.nodeSlice[n] == k) pts.emplace_back(m.X[n].y(), m.X[n].z());
      const auto cells = computeSliceVoronoi(pts, m.B, 0.0, m.h_s);
      double totalArea = 0;
      for (const auto& c : cells) {
        double sumEdges = 0;
        for (const auto& e : c.edges) sumEdges += e.length;
        // Dropped degenerate edges are shorter than kMinVoronoiEdge each: the edges close the perimeter.
        EXPECT_NEAR(sumEdges, c.perimeter, 10 * kMinVoronoiEdge) << "theta " << theta << " slice " << k;
        EXPECT_GT(c.area, 0);
        totalArea += c.area;
      }
      EXPECT_NEAR(totalArea, m.h_s * m.B, 1e-9 * m.h_s * m.B) << "theta " << theta;
      // Shared edges are symmetric: the length seen from A equals the length seen from B.
      for (std::size_t a = 0; a < cells.size(); ++a)
        for (const auto& e : cells[a].edges) {
          if (e.neighbour < 0) continue;
          bool found = false;
          for (const auto& f : cells[e.neighbour].edges)
            if (f.neighbour == static_cast<int>(a) && f.zShift == -e.zShift) {
              EXPECT_NEAR(f.length, e.length, kGeomTol);
              found = true;
            }
          EXPECT_TRUE(found);
        }
    }
  }
}

TEST(Geometry, CrisscrossPointsAlongMidPlaneAreDOverSinThetaApart) {
  for (double theta : {15.0, 30.0}) {
    GeometryParams p = smallParams(theta, 40, 8);
    const Model m = buildCrossply(p);
    // Crisscross points on y = yCrack: a ply-1 rod centre and a ply-2 rod centre both at yCrack.
    // Ply 1 rod j is at yCrack when x = xc - j s / tan; ply 2 rod i when x = xc + i s / tan.
    std::vector<double> xs;
    for (int j = -20; j <= 20; ++j) {
      const double x = m.xCrisscross - j * m.s / std::tan(m.theta);
      if (x < 0 || x > m.w_s) continue;
      // check a ply-2 rod passes through the same point
      const double y2 = rodCentreY(m, 1, -j, x);
      if (std::abs(y2 - m.yCrack) < kGeomTol) xs.push_back(x);
      EXPECT_NEAR(rodCentreY(m, 0, j, x), m.yCrack, kGeomTol);
    }
    ASSERT_GE(xs.size(), 2u);
    std::sort(xs.begin(), xs.end());
    for (std::size_t i = 1; i < xs.size(); ++i)
      EXPECT_NEAR(xs[i] - xs[i - 1], 1.0 / std::sin(m.theta), kGeomTol) << "theta " << theta;
    // Default phase 0 puts a crisscross point at the pre-crack tip a0_eff.
    EXPECT_NEAR(m.xCrisscross, m.a0Eff, kGeomTol);
  }
  GeometryParams p = smallParams(30, 40, 8);
  p.crisscross_phase = 0.25;
  const Model m = buildCrossply(p);
  EXPECT_NEAR(m.xCrisscross - m.a0Eff, 0.25 / std::sin(M_PI / 6), kGeomTol);
}

TEST(Geometry, PeriodicWrapJoinsPly2ToPly1OfTheNextPeriod) {
  const Model m = buildCrossply(smallParams(0, 6, 8));
  int wraps = 0;
  for (int i = 0; i < m.numInterfaces(); ++i) {
    const auto [a, b] = m.ifaceNodes[i];
    if (m.ifaceTag[i] == kTagInterlayer21) {
      ++wraps;
      EXPECT_EQ(m.nodePly[a], 1);
      EXPECT_EQ(m.nodePly[b], 0);
      EXPECT_EQ(m.ifaceZShift[i], 1);
      // B's image sits one ply thickness above A: z_B + B - z_A = t.
      const auto& g = m.ifaceGeom[i];
      const Vec3 xBimage = m.X[b] + Vec3(0, 0, m.B);
      EXPECT_NEAR(xBimage.z() - m.X[a].z(), m.t, kGeomTol);
      EXPECT_NEAR(((m.X[a] + g.armA) - (xBimage + g.armB)).norm(), 0.0, kGeomTol);  // one midpoint
    } else {
      EXPECT_EQ(m.ifaceZShift[i], 0);
    }
    const auto& g = m.ifaceGeom[i];
    // frame orthonormal and right-handed; normal along A->B
    EXPECT_NEAR((g.frame * g.frame.transpose() - Eigen::Matrix3d::Identity()).norm(), 0, kGeomTol);
    EXPECT_NEAR(g.frame.determinant(), 1.0, kGeomTol);
  }
  EXPECT_GT(wraps, 0);
}

TEST(Geometry, HandCountOnSmallTheta0Specimen) {
  // w_s = 6, h_s = 4, h_e = 0.3: 21 slices. Ply 1 rods at y = 0.75, 1.75, 2.75, 3.75; ply 2 at 0.25, 1.25,
  // 2.25, 3.25 (4 + 4 rods, every rod in every slice). Per slice: in-ply 3 + 3, interlayer 1-2: 7, wrap
  // 2-1: 7 => 20 interfaces. Pre-crack (a0 = 3 = 10 h_e: K = 10, slices 0..10, tip a0_eff = 10.25 h_e) cuts
  // across y = 2: ply 1 (1.75|2.75), ply 2 (1.25|2.25), interlayer 1.75-2.25 and wrap 2.25-(1.75 image) => 4 per
  // slice, 44 in all.
  const Model m = buildCrossply(smallParams(0, 6, 4));
  EXPECT_EQ(m.numSlices, 21);
  EXPECT_EQ(m.numRods(), 8);
  EXPECT_EQ(m.numNodes(), 8 * 21);
  EXPECT_EQ(m.numBeams(), 8 * 20);
  EXPECT_EQ(m.precrackBeams, 0);
  EXPECT_EQ(m.precrackLastSlice, 10);
  EXPECT_NEAR(m.a0Eff, 10.25 * 0.3, 1e-12);
  EXPECT_EQ(m.precrackInterfaces, 44);
  EXPECT_EQ(m.numInterfaces(), 20 * 21 - 44);
  std::map<int, int> byTag;
  for (auto t : m.ifaceTag) ++byTag[t];
  EXPECT_EQ(byTag[kTagPly1] + byTag[kTagPly2], 6 * 21 - 2 * 11);
  EXPECT_EQ(byTag[kTagInterlayer12], 7 * 21 - 11);
  EXPECT_EQ(byTag[kTagInterlayer21], 7 * 21 - 11);
  EXPECT_EQ(m.topNodes.size(), 2u * 21);
  EXPECT_EQ(m.bottomNodes.size(), 2u * 21);
  // Interface areas: tributary h_e (h_e/2 in the end slices) times d/sqrt(3) for interior edges.
  double area = 0;
  for (int i = 0; i < m.numInterfaces(); ++i)
    if (m.ifaceTag[i] == kTagPly1) area += m.ifaceGeom[i].area;
  // ply-1 in-ply edges are not clipped by the strip: 3 per slice, 2 in slices 0..10 -> total length w_s
  EXPECT_NEAR(area, (3 * m.w_s - 1 * (10 * 0.3 + 0.15)) / std::sqrt(3.0), 1e-9);
}

TEST(Geometry, PrecrackCutsRodsCrossingTheMidPlaneAtTheta30) {
  const Model m = buildCrossply(smallParams(30, 20, 8));
  EXPECT_GT(m.precrackBeams, 0);
  // No remaining beam behind the tip crosses the mid-plane; some ahead of it do.
  int aheadCrossing = 0;
  for (int b = 0; b < m.numBeams(); ++b) {
    const Vec3& xa = m.X[m.beamNodes[b][0]];
    const Vec3& xb = m.X[m.beamNodes[b][1]];
    const bool crosses = belowCrackPlane(m, xa.y()) != belowCrackPlane(m, xb.y());
    if (0.5 * (xa.x() + xb.x()) < m.a0Eff) EXPECT_FALSE(crosses);
    else aheadCrossing += crosses;
    EXPECT_NEAR((xb - xa).norm(), m.beamLength, kGeomTol);
  }
  EXPECT_GT(aheadCrossing, 0);
  // Every interface behind the tip stays on one side of the crack plane.
  for (int i = 0; i < m.numInterfaces(); ++i) {
    if (m.ifaceSlice[i] * m.h_e >= m.a0Eff) continue;
    const double yA = m.X[m.ifaceNodes[i][0]].y(), yB = m.X[m.ifaceNodes[i][1]].y();
    EXPECT_EQ(belowCrackPlane(m, yA), belowCrackPlane(m, yB));
  }
}

TEST(Geometry, RejectsImpossibleParameters) {
  GeometryParams p = smallParams(30);
  p.h_e = 1.5;
  EXPECT_THROW(buildCrossply(p), std::invalid_argument);
  p = smallParams(30);
  p.a0 = 10;
  EXPECT_THROW(buildCrossply(p), std::invalid_argument);
}
