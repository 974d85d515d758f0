#include "geometry/far_field.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <stdexcept>
#include <string>
#include <tuple>

namespace enamel {

namespace {

// The nodes of each rod, slice by slice (nodes are numbered slice by slice, so in order).
struct RodNodes {
  const Model& f;
  std::vector<std::vector<int>> nodes;
  explicit RodNodes(const Model& model) : f(model), nodes(model.numRods()) {
    for (int i = 0; i < f.numNodes(); ++i) nodes[f.nodeRod[i]].push_back(i);
  }
  /// The node of `rod` in slice k, -1 where the rod has none.
  int at(int rod, int k) const {
    const std::vector<int>& v = nodes[rod];
    const int k0 = f.nodeSlice[v.front()];
    return k >= k0 && k - k0 < static_cast<int>(v.size()) ? v[k - k0] : -1;
  }
};

// Which nodes stay: those of the full band, every `slices`-th slice, the first and last `slices` slices (the
// faces, where J is taken), the rod ends, the grips and the pre-crack's cut.
std::vector<char> chooseKeptNodes(const Model& f, const RodNodes& rods, int slices, double fullHalfHeight) {
  std::vector<char> keep(f.numNodes(), 0);
  for (int i = 0; i < f.numNodes(); ++i)
    keep[i] = std::abs(f.X[i].y() - f.yCrack) <= fullHalfHeight || f.nodeSlice[i] % slices == 0 ||
              f.nodeSlice[i] <= slices || f.nodeSlice[i] >= f.numSlices - 1 - slices;
  for (const auto& v : rods.nodes) keep[v.front()] = keep[v.back()] = 1;
  for (int n : f.topNodes) keep[n] = 1;
  for (int n : f.bottomNodes) keep[n] = 1;
  for (std::size_t c = 0; c < f.precrackBeamRod.size(); ++c)
    for (int dk : {0, 1}) {
      const int n = rods.at(f.precrackBeamRod[c], f.precrackBeamSlice[c] + dk);
      if (n >= 0) keep[n] = 1;
    }
  for (std::size_t c = 0; c < f.precrackIfaceRods.size(); ++c)
    for (int rod : f.precrackIfaceRods[c]) {
      const int n = rods.at(rod, f.precrackIfaceSlice[c]);
      if (n >= 0) keep[n] = 1;
    }
  return keep;
}

// Each interface goes to the nearest slice where both of its rods have a kept node; where there is none
// within +-slices (rods ending near each other), its own nodes are kept and the search is repeated.
std::vector<int> chooseInterfaceSlices(const Model& f, const RodNodes& rods, int slices, std::vector<char>& keep) {
  std::vector<int> target(f.numInterfaces(), -1);
  for (bool again = true; again;) {
    again = false;
    for (int i = 0; i < f.numInterfaces(); ++i) {
      const int rA = f.nodeRod[f.ifaceNodes[i][0]], rB = f.nodeRod[f.ifaceNodes[i][1]], k = f.ifaceSlice[i];
      target[i] = -1;
      for (int d = 0; d <= slices && target[i] < 0; ++d)
        for (int kk : {k - d, k + d}) {
          const int a = rods.at(rA, kk), b = rods.at(rB, kk);
          if (a >= 0 && b >= 0 && keep[a] && keep[b]) { target[i] = kk; break; }
        }
      if (target[i] < 0) {
        keep[f.ifaceNodes[i][0]] = keep[f.ifaceNodes[i][1]] = 1;
        again = true;
      }
    }
  }
  return target;
}

// The kept nodes, in their order (still slice by slice), into c; returns the full model's node -> c's node.
std::vector<int> copyKeptNodes(const Model& f, const std::vector<char>& keep, Model& c) {
  std::vector<int> newId(f.numNodes(), -1);
  c.X.clear(); c.nodeRod.clear(); c.nodeSlice.clear(); c.nodePly.clear();
  for (int i = 0; i < f.numNodes(); ++i) {
    if (!keep[i]) continue;
    newId[i] = c.numNodes();
    c.X.push_back(f.X[i]);
    c.nodeRod.push_back(f.nodeRod[i]);
    c.nodeSlice.push_back(f.nodeSlice[i]);
    c.nodePly.push_back(f.nodePly[i]);
  }
  for (int& n : c.topNodes) n = newId[n];
  for (int& n : c.bottomNodes) n = newId[n];
  return newId;
}

// Rod elements: consecutive kept nodes of a rod, except across the pre-crack's cut.
void joinRodElements(const Model& f, const RodNodes& rods, const std::vector<char>& keep, const std::vector<int>& newId,
                     Model& c) {
  std::vector<char> cutAfter(f.numNodes(), 0);  // the rod element starting at this node was cut
  for (std::size_t q = 0; q < f.precrackBeamRod.size(); ++q) cutAfter[rods.at(f.precrackBeamRod[q], f.precrackBeamSlice[q])] = 1;
  c.beamNodes.clear(); c.beamRod.clear(); c.beamSpan.clear();
  for (int rod = 0; rod < f.numRods(); ++rod) {
    int prev = -1;
    bool cut = false;
    for (int n : rods.nodes[rod]) {
      if (keep[n]) {
        if (prev >= 0 && !cut) {
          c.beamNodes.push_back({newId[prev], newId[n]});
          c.beamRod.push_back(rod);
          c.beamSpan.push_back(static_cast<std::int8_t>(f.nodeSlice[n] - f.nodeSlice[prev]));
        }
        prev = n;
        cut = false;
      }
      cut = cut || cutAfter[n];
    }
  }
}

// The interfaces landing on one pair of kept nodes (and periodic image): area summed, area-weighted point and
// normal, and the length along x they stand for.
struct InterfaceGroup {
  int slice, a, b, shift, first, members = 0;
  double area = 0, xLength = 0;
  Vec3 point = Vec3::Zero(), normal = Vec3::Zero();
};

std::vector<InterfaceGroup> groupInterfaces(const Model& f, const RodNodes& rods, const std::vector<int>& target,
                                            const std::vector<int>& newId, const Model& c) {
  std::vector<InterfaceGroup> groups;
  std::map<std::tuple<int, int, int>, int> groupOf;
  for (int i = 0; i < f.numInterfaces(); ++i) {
    const int k = target[i];
    const int a = newId[rods.at(f.nodeRod[f.ifaceNodes[i][0]], k)];
    const int b = newId[rods.at(f.nodeRod[f.ifaceNodes[i][1]], k)];
    const int shift = f.ifaceZShift[i];
    auto [it, fresh] = groupOf.try_emplace({a, b, shift}, static_cast<int>(groups.size()));
    if (fresh) groups.push_back(InterfaceGroup{k, a, b, shift, i});
    InterfaceGroup& g = groups[it->second];
    const cohesive::InterfaceGeometry& geo = f.ifaceGeom[i];
    ++g.members;
    g.area += geo.area;
    g.xLength += geo.area / f.ifaceEdgeLength[i];
    // the point moves with its two rods (by the mean of their shifts from slice k to the target slice)
    const Vec3 shiftA = c.X[a] - f.X[f.ifaceNodes[i][0]], shiftB = c.X[b] - f.X[f.ifaceNodes[i][1]];
    g.point += geo.area * (f.X[f.ifaceNodes[i][0]] + geo.armA + 0.5 * (shiftA + shiftB));
    g.normal += geo.area * geo.frame.row(0).transpose();
  }
  return groups;
}

// A lumped interface's geometry: the mean normal, the mean point moved into the nodes' slice (the force
// kernels take in-slice arms, cohesive::packInSlice), the summed area.
cohesive::InterfaceGeometry lumpedGeometry(const InterfaceGroup& g, const Model& c) {
  cohesive::InterfaceGeometry geo;
  const Vec3 n = g.normal.normalized();
  const Vec3 t1(1, 0, 0);
  geo.frame.row(0) = n;
  geo.frame.row(1) = t1;
  geo.frame.row(2) = n.cross(t1);
  Vec3 point = g.point / g.area;
  point.x() = c.X[g.a].x();
  geo.armA = point - c.X[g.a];
  geo.armB = point - (c.X[g.b] + Vec3(0, 0, g.shift * c.B));
  geo.area = g.area;
  return geo;
}

// The groups as c's interfaces, slice by slice; a group of one interface that stayed where it was unchanged.
void writeInterfaces(const Model& f, const std::vector<InterfaceGroup>& groups, Model& c) {
  std::vector<int> order(groups.size());
  for (std::size_t g = 0; g < groups.size(); ++g) order[g] = static_cast<int>(g);
  std::stable_sort(order.begin(), order.end(), [&](int x, int y) { return groups[x].slice < groups[y].slice; });
  c.ifaceNodes.clear(); c.ifaceGeom.clear(); c.ifaceTag.clear(); c.ifaceSlice.clear();
  c.ifaceEdgeLength.clear(); c.ifaceZShift.clear();
  for (int gi : order) {
    const InterfaceGroup& g = groups[gi];
    const int i = g.first;
    c.ifaceNodes.push_back({g.a, g.b});
    c.ifaceTag.push_back(f.ifaceTag[i]);
    c.ifaceSlice.push_back(g.slice);
    c.ifaceZShift.push_back(static_cast<std::int8_t>(g.shift));
    if (g.members == 1 && g.slice == f.ifaceSlice[i]) {
      c.ifaceGeom.push_back(f.ifaceGeom[i]);
      c.ifaceEdgeLength.push_back(f.ifaceEdgeLength[i]);
    } else {
      c.ifaceGeom.push_back(lumpedGeometry(g, c));
      c.ifaceEdgeLength.push_back(g.area / g.xLength);  // area / the length along x it stands for
    }
  }
}

}  // namespace

Model coarsenFarField(const Model& full, int slices, double fullHalfHeight) {
  if (slices <= 1) return full;
  if (!(fullHalfHeight >= 1.0))
    throw std::invalid_argument("reduced far field: the full band's half-height " + std::to_string(fullHalfHeight) +
                                " d must be at least 1 d (it holds the pre-crack's cut)");
  const RodNodes rods(full);
  std::vector<char> keep = chooseKeptNodes(full, rods, slices, fullHalfHeight);
  const std::vector<int> target = chooseInterfaceSlices(full, rods, slices, keep);
  Model c = full;  // constants, rods, pre-crack seeds
  c.farFieldSlices = slices;
  c.fullHalfHeight = fullHalfHeight;
  const std::vector<int> newId = copyKeptNodes(full, keep, c);
  joinRodElements(full, rods, keep, newId, c);
  writeInterfaces(full, groupInterfaces(full, rods, target, newId, c), c);
  numberNodesBySlice(c);  // nodes already in slice order; the rod elements in the order of their first node
  return c;
}

}  // namespace enamel
