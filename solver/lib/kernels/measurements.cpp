#include "kernels/measurements.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <utility>
#include <vector>

#include "kernels/kernels.hpp"

namespace enamel {

double strainEnergyOfBeams(const Operators& ops, const State& s) { return 0.5 * s.q.dot(ops.K * s.q); }

double strainEnergyOfInterfaces(const Model& m, const cohesive::Law& law, const State& s) {
  // Energies per interface in parallel, then one sum in a fixed order: the result (and so the energy
  // balance and its checks) does not depend on the thread count.
  std::vector<double> energy(m.numInterfaces());
#pragma omp parallel for schedule(static)
  for (int i = 0; i < m.numInterfaces(); ++i)
    energy[i] = m.ifaceGeom[i].area * cohesive::storedEnergyDensity(law, computeLocalOpening(m, s.q, i), s.lambdaMax[i]);
  return std::accumulate(energy.begin(), energy.end(), 0.0);
}

double fractureEnergyOfInterfaces(const Model& m, const cohesive::Law& law, const State& s) {
  double sum = 0;
  if (!law.isotropic()) {
    for (int i = 0; i < m.numInterfaces(); ++i) sum += m.ifaceGeom[i].area * s.ifaceDissipation[i];
    return sum;
  }
  for (int i = 0; i < m.numInterfaces(); ++i)
    sum += m.ifaceGeom[i].area * cohesive::dissipatedEnergyDensity(law, s.lambdaMax[i]);
  return sum;
}

void bookInterfaceDissipation(const Model& m, const cohesive::Law& law, State& s) {
  if (law.isotropic()) return;
  const int n = m.numInterfaces();
  if (s.lambdaMaxBooked.size() != static_cast<std::size_t>(n)) {
    s.lambdaMaxBooked.assign(n, 0.0);
    s.ifaceDissipation.assign(n, 0.0);
  }
#pragma omp parallel for schedule(static)
  for (int i = 0; i < n; ++i) {
    if (!(s.lambdaMax[i] > s.lambdaMaxBooked[i])) continue;
    s.ifaceDissipation[i] +=
        cohesive::dissipationIncrement(law, computeLocalOpening(m, s.q, i), s.lambdaMaxBooked[i], s.lambdaMax[i]);
    s.lambdaMaxBooked[i] = s.lambdaMax[i];
  }
}

int countFailedInterfaces(const cohesive::Law& law, const State& s) {
  int n = 0;
  for (double lm : s.lambdaMax) n += cohesive::isFailed(law, lm);
  return n;
}

int countInelasticInterfaces(const cohesive::Law& law, const State& s) {
  int n = 0;
  for (double lm : s.lambdaMax) n += cohesive::isInelastic(law, lm);
  return n;
}

namespace {
double distanceFromCrackPlane(const Model& m, const std::array<int, 2>& n) {
  return std::abs(0.5 * (m.X[n[0]].y() + m.X[n[1]].y()) - m.yCrack);
}
}  // namespace

// The runner warns when the reach comes near the loaded edges (the R-curve then depends on the specimen's
// height: docs/solver.md, "Reduced far field").
double inelasticInterfaceReach(const Model& m, const cohesive::Law& law, const State& s) {
  double reach = 0;
  for (int i = 0; i < m.numInterfaces(); ++i)
    if (cohesive::isInelastic(law, s.lambdaMax[i])) reach = std::max(reach, distanceFromCrackPlane(m, m.ifaceNodes[i]));
  return reach;
}

double brokenRodReach(const Model& m, const State& s) {
  double reach = 0;
  for (int e = 0; e < m.numBeams(); ++e)
    if (s.beamBroken[e]) reach = std::max(reach, distanceFromCrackPlane(m, m.beamNodes[e]));
  return reach;
}

double inelasticReach(const Model& m, const cohesive::Law& law, const State& s) {
  return std::max(inelasticInterfaceReach(m, law, s), brokenRodReach(m, s));
}

EventProgress measureEventProgress(const Model& m, const Materials& mat, const State& s) {
  EventProgress p;
  p.loadingTime = s.loadingTime;
  if (mat.rodsBreakable) {
    computeStressRatiosForBeams(m, mat, s.q, s.beamBroken, p.rods);
    for (int e = 0; e < m.numBeams(); ++e)
      if (s.beamBroken[e]) p.rods[e] = NAN;
  }
  const cohesive::Law& law = mat.law;
  const double deltaf = law.deltaf();
  p.interfaces.resize(m.numInterfaces());
#pragma omp parallel for schedule(static)
  for (int i = 0; i < m.numInterfaces(); ++i)
    p.interfaces[i] = cohesive::isFailed(law, s.lambdaMax[i])
        ? NAN : cohesive::effectiveSeparation(law, computeLocalOpening(m, s.q, i)) / deltaf;
  return p;
}

// The slope is stored per DOF (set with the grips, setup.cpp prescribeGrips): a test of the shape value's
// sign would take a bottom node at x = w_s, whose shape is -0.0, for a top node.
double sumGripForceTimesSlope(const Model& m, const Operators& ops, const State& s) {
  const double U = s.appliedDisplacement;
  double sum = 0;
  for (std::size_t i = 0; i < ops.prescribedDofs.size(); ++i) {
    const double dudx = ops.prescribedSlope[i] * U / m.w_s;
    sum += s.reaction[i] * dudx;
  }
  return sum;
}

double faceEnergyDensity(const Model& m, const Materials& mat, const State& s, int slice, int side) {
  double eb = 0, ebLong = 0, ei = 0;
  for (int e = 0; e < m.numBeams(); ++e) {
    if (s.beamBroken[e] || m.nodeSlice[m.beamNodes[e][side]] != slice) continue;
    const beam::Vec12 u = gatherElement(s.q, m.beamNodes[e][0], m.beamNodes[e][1]);
    const double energy = 0.5 * u.dot(mat.beamK[m.beamClass(e)] * u);
    if (m.beamSpan[e] == 1) eb += energy;
    else ebLong += energy / (m.beamSpan[e] * m.h_e);
  }
  for (int i = 0; i < m.numInterfaces(); ++i) {
    if (m.ifaceSlice[i] != slice) continue;
    const double w = cohesive::storedEnergyDensity(mat.law, computeLocalOpening(m, s.q, i), s.lambdaMax[i]);
    ei += m.hasFarField() ? m.ifaceEdgeLength[i] * w * (0.5 * m.h_e) : m.ifaceGeom[i].area * w;
  }
  return eb / m.h_e + ebLong + ei / (0.5 * m.h_e);
}

double computeJ(const Model& m, const Materials& mat, const Operators& ops, const State& s) {
  const double sumFdudx = sumGripForceTimesSlope(m, ops, s);
  const double Wleft = faceEnergyDensity(m, mat, s, 0, 0);
  const double Wright = faceEnergyDensity(m, mat, s, m.numSlices - 1, 1);
  return (-sumFdudx + Wright - Wleft) / m.B;
}

namespace {

// The crack cluster's graph: each element touches (rod, slice) points (an interface: its two rods in its
// slice; a rod element: its rod at its two slices); two elements are connected when they touch the same rod
// in the same or adjacent slices.
struct CrackGraph {
  struct Touch { long key; int elem; };
  int numSlices = 0;
  std::vector<Touch> touches;   // sorted by (key, elem) once built
  std::vector<double> elemX;    // x of each element
  std::vector<char> seed;       // the pre-crack's elements
  std::vector<char> offPlane;   // a failed interface whose two rods lie on one side of the crack plane (a kink)
  void add(double x, bool isSeed, std::initializer_list<std::pair<int, int>> pts, bool kink = false) {
    const int id = static_cast<int>(elemX.size());
    elemX.push_back(x);
    seed.push_back(isSeed);
    offPlane.push_back(kink);
    for (auto [rod, slice] : pts) touches.push_back({static_cast<long>(rod) * numSlices + slice, id});
  }
};

CrackGraph collectCrackElements(const Model& m, const cohesive::Law& law, const State& s) {
  CrackGraph g;
  g.numSlices = m.numSlices;
  for (std::size_t i = 0; i < m.precrackIfaceRods.size(); ++i)
    g.add(m.precrackIfaceSlice[i] * m.h_e, true,
          {{m.precrackIfaceRods[i][0], m.precrackIfaceSlice[i]}, {m.precrackIfaceRods[i][1], m.precrackIfaceSlice[i]}});
  for (std::size_t i = 0; i < m.precrackBeamRod.size(); ++i)
    g.add((m.precrackBeamSlice[i] + 0.5) * m.h_e, true,
          {{m.precrackBeamRod[i], m.precrackBeamSlice[i]}, {m.precrackBeamRod[i], m.precrackBeamSlice[i] + 1}});
  for (int i = 0; i < m.numInterfaces(); ++i) {
    if (!cohesive::isFailed(law, s.lambdaMax[i])) continue;
    const int k = m.ifaceSlice[i];
    const int a = m.ifaceNodes[i][0], b = m.ifaceNodes[i][1];
    const bool kink = belowCrackPlane(m, m.X[a].y()) == belowCrackPlane(m, m.X[b].y());
    g.add(k * m.h_e, false, {{m.nodeRod[a], k}, {m.nodeRod[b], k}}, kink);
  }
  for (int e = 0; e < m.numBeams(); ++e) {
    if (!s.beamBroken[e]) continue;
    const int k = m.nodeSlice[m.beamNodes[e][0]];
    g.add((k + 0.5) * m.h_e, false, {{m.beamRod[e], k}, {m.beamRod[e], k + 1}});
  }
  std::sort(g.touches.begin(), g.touches.end(), [](const CrackGraph::Touch& x, const CrackGraph::Touch& y) {
    return x.key < y.key || (x.key == y.key && x.elem < y.elem);
  });
  return g;
}

// Which elements are connected to the pre-crack (depth-first from its elements).
std::vector<char> connectedToPrecrack(const CrackGraph& g) {
  const int ns = g.numSlices;
  std::vector<std::vector<int>> elemTouches(g.elemX.size());
  for (const auto& t : g.touches) elemTouches[t.elem].push_back(static_cast<int>(t.key));
  auto range = [&](long key) {
    auto lo = std::lower_bound(g.touches.begin(), g.touches.end(), key,
                               [](const CrackGraph::Touch& t, long k) { return t.key < k; });
    auto hi = lo;
    while (hi != g.touches.end() && hi->key == key) ++hi;
    return std::make_pair(lo, hi);
  };
  std::vector<char> visited(g.elemX.size(), 0);
  std::vector<int> stack;
  for (std::size_t i = 0; i < g.elemX.size(); ++i)
    if (g.seed[i]) { visited[i] = 1; stack.push_back(static_cast<int>(i)); }
  while (!stack.empty()) {
    const int e = stack.back();
    stack.pop_back();
    for (int key : elemTouches[e]) {
      const int slice = key % ns;
      for (int dk = -1; dk <= 1; ++dk) {
        if (slice + dk < 0 || slice + dk >= ns) continue;
        auto [lo, hi] = range(key + dk);
        for (auto it = lo; it != hi; ++it)
          if (!visited[it->elem]) { visited[it->elem] = 1; stack.push_back(it->elem); }
      }
    }
  }
  return visited;
}

CrackCluster summariseCluster(const Model& m, const CrackGraph& g) {
  const std::vector<char> connected = connectedToPrecrack(g);
  double maxX = 0;
  CrackCluster c;
  for (std::size_t e = 0; e < connected.size(); ++e) {
    if (!connected[e]) continue;
    maxX = std::max(maxX, g.elemX[e]);
    c.offPlaneInterfaces += g.offPlane[e];
  }
  c.advance = std::max(0.0, maxX - m.a0Eff);
  return c;
}

}  // namespace

CrackCluster measureCrackCluster(const Model& m, const cohesive::Law& law, const State& s) {
  return summariseCluster(m, collectCrackElements(m, law, s));
}

double measureCrackAdvance(const Model& m, const cohesive::Law& law, const State& s) {
  return measureCrackCluster(m, law, s).advance;
}

double computeGripLoad(const Operators& ops, const State& s) {
  double P = 0;
  for (std::size_t i = 0; i < ops.prescribedDofs.size(); ++i) P += s.reaction[i] * ops.prescribedShape[i];
  return P;
}

double balanceWorkFloor(double Gamma, double B) { return 0.1 * Gamma * B; }

double energyBalanceError(double external, double storedKineticDissipated, double workFloor) {
  const double scale = std::max(std::abs(external), workFloor);
  return scale > 0 ? (external - storedKineticDissipated) / scale : 0.0;
}

}  // namespace enamel
