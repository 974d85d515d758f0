#include "geometry/geometry.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace enamel {

const char* interfaceTagName(int tag) {
  switch (tag) {
    case kTagPly1: return "ply 1";
    case kTagPly2: return "ply 2";
    case kTagInterlayer12: return "interlayer 1-2";
    case kTagInterlayer21: return "interlayer 2-1 (periodic wrap)";
  }
  return "unknown";
}

Vec3 Model::rodDirection(int ply) const {
  const double sign = ply == 0 ? 1.0 : -1.0;
  return Vec3(std::cos(theta), sign * std::sin(theta), 0.0);
}

// The pre-crack tip at a quarter point of the slice lattice (geometry.hpp, docs/model.md Geometry).
PrecrackTip precrackTip(double a0, double h_e) {
  PrecrackTip tip;
  tip.lastSlice = static_cast<int>(std::floor(a0 / h_e + kTipSnapTolerance));
  tip.a0Eff = (tip.lastSlice + 0.25) * h_e;
  return tip;
}

bool belowCrackPlane(const Model& m, double y) { return y < m.yCrack - kCrackPlaneTolerance * m.d; }

// Rod centre lines (docs/model.md), with the origin of x put on a crisscross point of the mid-plane:
//   ply 1:  y = yCrack + j s + (x - xCrisscross) tan(theta)
//   ply 2:  y = yCrack + j s - (x - xCrisscross) tan(theta)
// so that rod 0 of both plies crosses the mid-plane at xCrisscross. At theta = 0 there is no crisscross:
// the plies are hexagonally packed, ply 1 at yCrack - d/4 + j d and ply 2 at yCrack + d/4 + j d, and the
// mid-plane runs between the two rows.
double rodCentreY(const Model& m, int ply, int j, double x) {
  if (m.theta == 0.0) return m.yCrack + (ply == 0 ? -0.25 : 0.25) * m.d + j * m.s;
  const double sign = ply == 0 ? 1.0 : -1.0;
  return m.yCrack + j * m.s + sign * (x - m.xCrisscross) * std::tan(m.theta);
}

namespace {

// A convex polygon with a label per edge (edge e runs from vertex e to vertex e+1).
struct LabelledPolygon {
  std::vector<Vec2> v;
  std::vector<int> label;  // index of the clipping candidate that made this edge, or -1 for the strip
};

// Keep the part of `poly` where (x - c) . n <= h (Sutherland-Hodgman); the new edge along the line gets `lab`.
LabelledPolygon clipByHalfPlane(const LabelledPolygon& poly, const Vec2& c, const Vec2& n, double h, int lab) {
  LabelledPolygon out;
  const std::size_t nv = poly.v.size();
  for (std::size_t e = 0; e < nv; ++e) {
    const Vec2& a = poly.v[e];
    const Vec2& b = poly.v[(e + 1) % nv];
    const double fa = (a - c).dot(n) - h, fb = (b - c).dot(n) - h;
    const bool ina = fa <= 0, inb = fb <= 0;
    if (ina) {
      out.v.push_back(a);
      out.label.push_back(poly.label[e]);
    }
    if (ina != inb) {
      const Vec2 cross = a + (b - a) * (fa / (fa - fb));
      out.v.push_back(cross);
      out.label.push_back(ina ? lab : poly.label[e]);
    }
  }
  return out;
}

}  // namespace

// Each cell = the strip box around point i clipped by the bisector half-planes of every other point (and
// its z-images) within reach. The edge made by a bisector is the Voronoi edge shared with that neighbour.
std::vector<VoronoiCell> computeSliceVoronoi(const std::vector<Vec2>& points, double period, double yLo,
                                             double yHi, double minEdge) {
  const int n = static_cast<int>(points.size());
  const double reach = 2.0 * period + 1.0;  // generous: Voronoi neighbours of these packings are within ~1.2 d
  std::vector<VoronoiCell> cells(n);
  struct Candidate { int j; int shift; };
  std::vector<Candidate> cand;
  for (int i = 0; i < n; ++i) {
    const Vec2& p = points[i];
    LabelledPolygon poly;
    poly.v = {Vec2(yLo, p.y() - period), Vec2(yHi, p.y() - period), Vec2(yHi, p.y() + period),
              Vec2(yLo, p.y() + period)};
    poly.label = {-1, -1, -1, -1};  // the z-sides of this box are always cut away by the z-images
    cand.clear();
    for (int j = 0; j < n; ++j) {
      if (std::abs(points[j].x() - p.x()) > reach) continue;
      for (int shift = -1; shift <= 1; ++shift) {
        if (j == i && shift == 0) continue;
        cand.push_back({j, shift});
      }
    }
    for (std::size_t c = 0; c < cand.size(); ++c) {
      const Vec2 q = points[cand[c].j] + Vec2(0, cand[c].shift * period);
      const Vec2 dq = q - p;
      // |x - p| <= |x - q|  <=>  (x - p) . (q - p) <= |q - p|^2 / 2
      poly = clipByHalfPlane(poly, p, dq, 0.5 * dq.squaredNorm(), static_cast<int>(c));
      if (poly.v.empty()) break;
    }
    VoronoiCell& cell = cells[i];
    cell.polygon = poly.v;
    const std::size_t nv = poly.v.size();
    for (std::size_t e = 0; e < nv; ++e) {
      const Vec2& a = poly.v[e];
      const Vec2& b = poly.v[(e + 1) % nv];
      const double len = (b - a).norm();
      cell.area += 0.5 * (a.x() * b.y() - b.x() * a.y());
      cell.perimeter += len;
      if (len <= minEdge) continue;
      VoronoiEdge edge;
      edge.neighbour = poly.label[e] < 0 ? -1 : cand[poly.label[e]].j;
      edge.zShift = poly.label[e] < 0 ? 0 : cand[poly.label[e]].shift;
      edge.length = len;
      edge.midpoint = 0.5 * (a + b);
      cell.edges.push_back(edge);
    }
  }
  return cells;
}

// Renumber the nodes slice by slice (within a slice in their order of creation: by ply, rod), so that the
// nodes of a slice, which its interfaces join, are contiguous in memory, and the rod elements in the order of
// their first node: the force kernels work slice by slice on data that stays in cache, and a loop over rod
// elements reads nodes in the order they are stored. Interfaces keep their order (slice by slice).
void numberNodesBySlice(Model& m) {
  std::vector<int> order(m.numNodes());
  for (int i = 0; i < m.numNodes(); ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return m.nodeSlice[a] < m.nodeSlice[b]; });
  std::vector<int> newId(m.numNodes());
  for (int i = 0; i < m.numNodes(); ++i) newId[order[i]] = i;
  auto permute = [&](auto& v) {
    auto old = v;
    for (int i = 0; i < m.numNodes(); ++i) v[i] = old[order[i]];
  };
  permute(m.X);
  permute(m.nodeRod);
  permute(m.nodeSlice);
  permute(m.nodePly);
  for (auto& ab : m.beamNodes) ab = {newId[ab[0]], newId[ab[1]]};
  // rod elements in the order of their first node (stable: within a slice by rod)
  std::vector<int> beams(m.numBeams());
  for (int e = 0; e < m.numBeams(); ++e) beams[e] = e;
  std::stable_sort(beams.begin(), beams.end(), [&](int a, int b) { return m.beamNodes[a][0] < m.beamNodes[b][0]; });
  const auto oldNodes = m.beamNodes;
  const auto oldRod = m.beamRod;
  const auto oldSpan = m.beamSpan;
  for (int e = 0; e < m.numBeams(); ++e) {
    m.beamNodes[e] = oldNodes[beams[e]];
    m.beamRod[e] = oldRod[beams[e]];
    m.beamSpan[e] = oldSpan[beams[e]];
  }
  for (auto& ab : m.ifaceNodes) ab = {newId[ab[0]], newId[ab[1]]};
  for (int& n : m.topNodes) n = newId[n];
  for (int& n : m.bottomNodes) n = newId[n];
}
namespace {

void checkGeometryParams(const GeometryParams& p) {
  if (!(p.theta_deg >= 0 && p.theta_deg <= 45)) throw std::invalid_argument("theta_D must be in [0, 45] deg");
  if (!(p.h_e > 0 && p.h_e <= 1)) throw std::invalid_argument("h_e must be in (0, 1] d");
  if (!(p.w_s >= 2 * p.h_e && p.h_s >= 2)) throw std::invalid_argument("specimen too small");
  if (!(p.a0 > 0 && p.a0 < p.w_s)) throw std::invalid_argument("a0 must be in (0, w_s)");
}

// The model's constants: packing, specimen, slices, crack plane, crisscross point.
Model modelConstants(const GeometryParams& p) {
  Model m;
  m.theta = p.theta_deg * M_PI / 180.0;
  m.s = m.d / std::cos(m.theta);
  m.t = std::sqrt(3.0) / 2.0 * m.d;
  m.B = 2.0 * m.t;
  m.w_s = p.w_s;
  m.h_s = p.h_s;
  m.a0 = p.a0;
  m.numSlices = static_cast<int>(std::lround(p.w_s / p.h_e)) + 1;
  m.h_e = p.w_s / (m.numSlices - 1);
  m.yCrack = 0.5 * p.h_s;
  const PrecrackTip tip = precrackTip(p.a0, m.h_e);
  m.precrackLastSlice = tip.lastSlice;
  m.a0Eff = tip.a0Eff;
  // The crisscross lattice: its origin is the tip (its rods cross the mid-plane inside the intact element
  // [K, K+1]) or half a slice behind it (inside the last cut element [K-1, K]: the paper's Fig. 4), shifted by
  // crisscross_phase crisscross spacings d/sin(theta) ahead.
  const double origin = p.crisscrossCutAtTip ? tip.a0Eff - 0.5 * m.h_e : tip.a0Eff;
  m.xCrisscross = m.theta > 0 ? origin + p.crisscross_phase * m.d / std::sin(m.theta) : origin;
  m.beamLength = m.h_e / std::cos(m.theta);
  return m;
}

// One rod (ply, j) with its nodes in slices first .. first + count - 1 and the rod elements between them; a
// rod element [k-1, k] with k <= K (precrackTip) that crosses the mid-plane is cut by the pre-crack.
void addRod(Model& m, const GeometryParams& p, int ply, int j, int first, int count,
            std::vector<std::vector<int>>& sliceNodes) {
  const int rod = m.numRods();
  m.rodPly.push_back(static_cast<std::int8_t>(ply));
  m.rodIndex.push_back(j);
  for (int k = first; k < first + count; ++k) {
    const double x = k * m.h_e;
    const int node = m.numNodes();
    m.X.emplace_back(x, rodCentreY(m, ply, j, x), ply == 0 ? 0.0 : m.t);
    m.nodeRod.push_back(rod);
    m.nodeSlice.push_back(k);
    m.nodePly.push_back(static_cast<std::int8_t>(ply));
    sliceNodes[k].push_back(node);
    if (k == first) continue;
    const bool crosses = belowCrackPlane(m, m.X[node - 1].y()) != belowCrackPlane(m, m.X[node].y());
    if (p.precrack && crosses && k <= m.precrackLastSlice) {
      ++m.precrackBeams;
      m.precrackBeamRod.push_back(rod);
      m.precrackBeamSlice.push_back(k - 1);
    } else {
      m.beamNodes.push_back({node - 1, node});
      m.beamRod.push_back(rod);
      m.beamSpan.push_back(1);
    }
  }
}

// Rods and nodes: the node of rod (ply, j) in slice k exists when its centre lies in [0, h_s); returns the
// node ids of each slice, sorted by (ply, y).
std::vector<std::vector<int>> addRodsAndNodes(Model& m, const GeometryParams& p) {
  const double tanT = std::tan(m.theta);
  const int jSpan = static_cast<int>(std::ceil((p.h_s + p.w_s * tanT) / m.s)) + 2;
  std::vector<std::vector<int>> sliceNodes(m.numSlices);
  for (int ply = 0; ply < 2; ++ply)
    for (int j = -jSpan; j <= jSpan; ++j) {
      int first = -1, count = 0;
      for (int k = 0; k < m.numSlices; ++k) {
        const double y = rodCentreY(m, ply, j, k * m.h_e);
        if (y >= 0 && y < p.h_s) {
          if (first < 0) first = k;
          ++count;
        }
      }
      if (count >= 2) addRod(m, p, ply, j, first, count, sliceNodes);  // a single node would carry no beam
    }
  return sliceNodes;
}

// One interface between nodes nA (lower z) and nB (+ shift periods in z) at the Voronoi edge's midpoint.
void addInterface(Model& m, int k, int nA, int nB, int shift, const Vec3& mid, double area, double edgeLength) {
  const Vec3 xA = m.X[nA], xB = m.X[nB] + Vec3(0, 0, shift * m.B);
  cohesive::InterfaceGeometry g;
  const Vec3 nrm = (xB - xA).normalized();
  const Vec3 t1(1, 0, 0);
  g.frame.row(0) = nrm;
  g.frame.row(1) = t1;
  g.frame.row(2) = nrm.cross(t1);
  g.armA = mid - xA;
  g.armB = mid - xB;
  g.area = area;
  const int plyA = m.nodePly[nA], plyB = m.nodePly[nB];
  const std::int8_t tag = plyA == plyB ? (plyA == 0 ? kTagPly1 : kTagPly2) : (plyA == 0 ? kTagInterlayer12 : kTagInterlayer21);
  m.ifaceNodes.push_back({nA, nB});
  m.ifaceGeom.push_back(g);
  m.ifaceTag.push_back(tag);
  m.ifaceSlice.push_back(k);
  m.ifaceEdgeLength.push_back(edgeLength);
  m.ifaceZShift.push_back(static_cast<std::int8_t>(shift));
}

// The interfaces of slice k: Voronoi neighbours, periodic in z; those across the mid-plane in slices k <= K
// (precrackTip) are the pre-crack.
void addInterfacesOfSlice(Model& m, const GeometryParams& p, int k, const std::vector<int>& ids) {
  std::vector<Vec2> pts;
  pts.reserve(ids.size());
  for (int id : ids) pts.emplace_back(m.X[id].y(), m.X[id].z());
  const std::vector<VoronoiCell> cells = computeSliceVoronoi(pts, m.B, 0.0, p.h_s);
  const double x = k * m.h_e;
  const double tributary = (k == 0 || k == m.numSlices - 1) ? 0.5 * m.h_e : m.h_e;
  for (int a = 0; a < static_cast<int>(ids.size()); ++a)
    for (const VoronoiEdge& e : cells[a].edges) {
      if (e.neighbour < 0) continue;
      // Each pair once: from the lower index, or for a pair with itself-free shift, the positive shift.
      if (e.neighbour < a || (e.neighbour == a && e.zShift < 0)) continue;
      if (e.neighbour == a) continue;  // a rod's own z-image is never its neighbour in these packings
      const int A = ids[a], Bn = ids[e.neighbour];
      // Orient every pair so that the wrap (if any) goes from ply 2 up to ply 1: A = lower z.
      int nA = A, nB = Bn, shift = e.zShift;
      const Vec3 xB0 = m.X[Bn] + Vec3(0, 0, e.zShift * m.B);
      if (xB0.z() < m.X[A].z() || (xB0.z() == m.X[A].z() && xB0.y() < m.X[A].y())) {
        std::swap(nA, nB);
        shift = -shift;
      }
      const Vec3 xA = m.X[nA], xB = m.X[nB] + Vec3(0, 0, shift * m.B);
      if (p.precrack && k <= m.precrackLastSlice && belowCrackPlane(m, xA.y()) != belowCrackPlane(m, xB.y())) {
        ++m.precrackInterfaces;
        m.precrackIfaceRods.push_back({m.nodeRod[nA], m.nodeRod[nB]});
        m.precrackIfaceSlice.push_back(k);
        continue;
      }
      const Vec3 mid(x, e.midpoint.x(), e.midpoint.y() + (nA == A ? 0.0 : shift * m.B));
      addInterface(m, k, nA, nB, shift, mid, tributary * e.length, e.length);
    }
}

// The boundary sets: the extreme node of each ply in a slice.
void addGripNodesOfSlice(Model& m, const std::vector<int>& ids) {
  for (int ply = 0; ply < 2; ++ply) {
    int top = -1, bottom = -1;
    for (int id : ids) {
      if (m.nodePly[id] != ply) continue;
      if (top < 0 || m.X[id].y() > m.X[top].y()) top = id;
      if (bottom < 0 || m.X[id].y() < m.X[bottom].y()) bottom = id;
    }
    if (top >= 0) m.topNodes.push_back(top);
    if (bottom >= 0) m.bottomNodes.push_back(bottom);
  }
}

}  // namespace

Model buildCrossply(const GeometryParams& p) {
  checkGeometryParams(p);
  Model m = modelConstants(p);
  const std::vector<std::vector<int>> sliceNodes = addRodsAndNodes(m, p);
  for (int k = 0; k < m.numSlices; ++k) {
    addInterfacesOfSlice(m, p, k, sliceNodes[k]);
    addGripNodesOfSlice(m, sliceNodes[k]);
  }
  numberNodesBySlice(m);
  return m;
}

}  // namespace enamel
