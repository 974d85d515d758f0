// The rods' damping b K taken implicitly in the lumped step (rod_damping.hpp): the block factorisation of
// H = s M + c K along each rod, and its solve.
#include "integrators/rod_damping.hpp"

#include <algorithm>
#include <cstring>
#include <map>
#include <sstream>

#include "base/errors.hpp"

#if defined(__SSE2__)
#include <xmmintrin.h>
#endif

namespace enamel {

namespace {

using Mat6 = RodDampingSolve::Mat6;
using Vec6 = Eigen::Matrix<double, 6, 1>;

// Node i's row of K in node blocks: D = K_ii, E = K_ip with p the node before i on its rod, and the nodes before
// and after it. K is symmetric, so the six columns of node i hold its row: entry (6 j + b, 6 i + a) is K_ij(a, b).
struct RodRow {
  Mat6 D = Mat6::Zero(), E = Mat6::Zero();
  int before = -1, after = -1;
};

RodRow rodRowOfK(const SpMat& K, int node) {
  RodRow row;
  for (int a = 0; a < 6; ++a)
    for (SpMat::InnerIterator it(K, 6 * node + a); it; ++it) {
      const int j = static_cast<int>(it.row()) / 6, b = static_cast<int>(it.row()) % 6;
      if (j == node) {
        row.D(a, b) = it.value();
        continue;
      }
      int& side = j < node ? row.before : row.after;
      if (side >= 0 && side != j) {
        std::ostringstream msg;
        msg << "rod damping: node " << node << " has two rod neighbours on one side (" << side << " and " << j
            << "): the rods' stiffness is not one chain per rod";
        throw IntegratorError(msg.str());
      }
      side = j;
      if (j < node) row.E(a, b) = it.value();
    }
  return row;
}

// H's blocks of node i from its row of K: D_H = s M_i + c D (the prescribed DOFs' rows and columns the identity's),
// E_H = c E (zero in a prescribed DOF's row of i or column of p).
void blocksOfH(const RodDampingSolve& f, const std::vector<char>& prescribed, int node, const VecX& mass,
               RodRow& row) {
  row.D *= f.c;
  row.E *= f.c;
  for (int a = 0; a < 6; ++a) {
    row.D(a, a) += f.scale * mass[6 * node + a];
    if (prescribed[6 * node + a]) {
      row.D.row(a).setZero(), row.D.col(a).setZero(), row.D(a, a) = 1;
      row.E.row(a).setZero();
    }
    if (row.before >= 0 && prescribed[6 * row.before + a]) row.E.col(a).setZero();
  }
}

// The factors of node i from its H blocks and the S^-1 of the node before it.
RodDampingSolve::Factors factorsOfNode(const RodRow& row, const Mat6* SinvBefore, int node) {
  RodDampingSolve::Factors out;
  Mat6 S = row.D;
  out.P.setZero();
  if (SinvBefore) {
    out.P = row.E * *SinvBefore;
    S -= out.P * row.E.transpose();
  }
  S = 0.5 * (S + S.transpose());
  const Eigen::LLT<Mat6> llt(S);
  if (llt.info() != Eigen::Success) {
    std::ostringstream msg;
    msg << "rod damping: the block of node " << node << " of s M + c K is not positive definite";
    throw IntegratorError(msg.str());
  }
  out.Sinv = llt.solve(Mat6::Identity());
  return out;
}

// The distinct factor pairs, found by their bits.
struct FactorTable {
  std::map<std::array<double, 72>, int> index;
  int find(RodDampingSolve& f, const RodDampingSolve::Factors& x) {
    std::array<double, 72> key;
    std::memcpy(key.data(), x.Sinv.data(), 36 * sizeof(double));
    std::memcpy(key.data() + 36, x.P.data(), 36 * sizeof(double));
    const auto [it, added] = index.emplace(key, static_cast<int>(f.factors.size()));
    if (added) f.factors.push_back(x);
    return it->second;
  }
};

std::vector<char> prescribedMask(int dofs, const std::vector<int>& prescribedDofs) {
  std::vector<char> mask(dofs, 0);
  for (int dof : prescribedDofs) mask[dof] = 1;
  return mask;
}

// The prescribed DOFs' columns in the free rows (c K(f, p)), by the free row's node, and their rows of K.
void collectGripCouplings(const SpMat& K, const std::vector<int>& prescribedDofs, const std::vector<char>& prescribed,
                          RodDampingSolve& f) {
  f.gripColumns.clear(), f.gripRowStart.assign(1, 0), f.gripRowDof.clear(), f.gripRowK.clear();
  for (int p : prescribedDofs) {
    for (SpMat::InnerIterator it(K, p); it; ++it) {
      const int r = static_cast<int>(it.row());
      f.gripRowDof.push_back(r), f.gripRowK.push_back(it.value());
      if (!prescribed[r]) f.gripColumns.push_back({r, p, f.c * it.value()});
    }
    f.gripRowStart.push_back(static_cast<int>(f.gripRowDof.size()));
  }
  std::stable_sort(f.gripColumns.begin(), f.gripColumns.end(),
                   [](const auto& a, const auto& b) { return a.freeDof / 6 < b.freeDof / 6; });
  const int nodes = static_cast<int>(prescribed.size() / 6);
  f.nodeGripStart.assign(nodes + 1, 0);
  for (const auto& g : f.gripColumns) ++f.nodeGripStart[g.freeDof / 6 + 1];
  for (int node = 0; node < nodes; ++node) f.nodeGripStart[node + 1] += f.nodeGripStart[node];
}

// Each distinct pair's two group blocks; refused where a factor couples the groups.
void splitFactorsByGroups(RodDampingSolve& f) {
  constexpr auto& G = RodDampingSolve::kGroups;
  for (std::size_t i = f.groupFactors.size(); i < f.factors.size(); ++i) {
    const RodDampingSolve::Factors& x = f.factors[i];
    RodDampingSolve::GroupFactors out;
    for (int g = 0; g < 2; ++g)
      for (int k = 0; k < 3; ++k) {
        out.Sinv[g][k] = out.P[g][k] = out.PT[g][k] = RodDampingSolve::Quad{0, 0, 0, 0};
        for (int r = 0; r < 3; ++r) {
          out.Sinv[g][k][r] = x.Sinv(G[g][r], G[g][k]);
          out.P[g][k][r] = x.P(G[g][r], G[g][k]);
          out.PT[g][k][r] = x.P(G[g][k], G[g][r]);
        }
      }
    for (int r : G[0])
      for (int k : G[1])
        if (x.Sinv(r, k) != 0 || x.Sinv(k, r) != 0 || x.P(r, k) != 0 || x.P(k, r) != 0)
          throw IntegratorError("rod damping: a rod's factors couple (ux, uy, rz) with (uz, rx, ry): a rod out of "
                                "its xy-plane, which the rods' solve does not take");
    f.groupFactors.push_back(out);
  }
}

// Factorise the nodes that `redo` names, in ascending order (a node's factors need those of the node before it),
// and keep each node's chain and diagonal. Returns how many were factorised.
template <class Redo>
long factoriseNodes(const SpMat& K, const VecX& mass, const std::vector<char>& prescribed, RodDampingSolve& f,
                    Redo redo) {
  FactorTable table;
  for (std::size_t i = 0; i < f.factors.size(); ++i) {
    std::array<double, 72> key;
    std::memcpy(key.data(), f.factors[i].Sinv.data(), 36 * sizeof(double));
    std::memcpy(key.data() + 36, f.factors[i].P.data(), 36 * sizeof(double));
    table.index.emplace(key, static_cast<int>(i));
  }
  const int nodes = static_cast<int>(mass.size() / 6);
  std::vector<char> redone(nodes, 0);
  long count = 0;
  for (int node = 0; node < nodes; ++node) {
    RodRow row = rodRowOfK(K, node);
    std::array<double, 6> diag;
    for (int a = 0; a < 6; ++a) diag[a] = row.D(a, a);
    const bool changed = diag != f.diag[node] || row.before != f.before[node];
    f.before[node] = row.before, f.after[node] = row.after, f.diag[node] = diag;
    if (!redo(node, changed, row.before >= 0 && redone[row.before])) continue;
    blocksOfH(f, prescribed, node, mass, row);
    const Mat6* SinvBefore = row.before >= 0 ? &f.factors[f.factorsOf[row.before]].Sinv : nullptr;
    f.factorsOf[node] = table.find(f, factorsOfNode(row, SinvBefore, node));
    redone[node] = 1;
    ++count;
  }
  return count;
}

// Subnormal results flushed to zero while it lives (this thread's MXCSR, restored after): the sweeps carry a
// rod's values down the rod with a factor below one per node, so a DOF that moves little (the out-of-plane group)
// decays through the subnormals, which cost the CPU ~100 cycles an operation. A flushed value is below 2.2e-308.
struct FlushSubnormals {
#if defined(__SSE2__)
  unsigned saved = _mm_getcsr();
  FlushSubnormals() { _mm_setcsr(saved | 0x8040); }  // FTZ (bit 15) and DAZ (bit 6)
  ~FlushSubnormals() { _mm_setcsr(saved); }
#endif
};

// The sweeps compiled for three CPUs, as node_rows.cpp's rows (the loader picks one; x86-64-v3 and v4 the same bits,
// the default x86-64 within round-off of them).
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
#define ENAMEL_CPU_CLONES [[gnu::target_clones("arch=x86-64-v4", "arch=x86-64-v3", "default")]]
#else
#define ENAMEL_CPU_CLONES
#endif

using Quad = RodDampingSolve::Quad;
constexpr auto& kGroups = RodDampingSolve::kGroups;

// column k of a 3 x 3 block times x[kGroups[g][k]], summed over k (always inlined: no quad crosses a call, so
// GCC's note on the AVX calling convention does not apply)
#pragma GCC diagnostic ignored "-Wpsabi"
[[gnu::always_inline]] inline Quad times(const Quad* B, const double* x, int g) {
  return B[0] * x[kGroups[g][0]] + B[1] * x[kGroups[g][1]] + B[2] * x[kGroups[g][2]];
}

// Forward: y_i = rhs_i - P_i y_p, into v, over one lane's nodes in ascending order.
ENAMEL_CPU_CLONES void sweepForward(const RodDampingSolve& f, const std::vector<int>& nodes, const VecX& vStar, VecX& v) {
  for (int node : nodes) {
    double* y = v.data() + 6 * node;
    for (int d = 0; d < 6; ++d) y[d] = f.rhsScale[6 * node + d] * vStar[6 * node + d];
    for (int e = f.nodeGripStart[node]; e < f.nodeGripStart[node + 1]; ++e)
      v[f.gripColumns[e].freeDof] -= f.gripColumns[e].cK * vStar[f.gripColumns[e].gripDof];
    const int p = f.before[node];
    if (p < 0) continue;
    const RodDampingSolve::GroupFactors& F = f.groupFactors[f.factorsOf[node]];
    const Quad y0 = times(F.P[0], v.data() + 6 * p, 0), y1 = times(F.P[1], v.data() + 6 * p, 1);
    for (int k = 0; k < 3; ++k) y[kGroups[0][k]] -= y0[k], y[kGroups[1][k]] -= y1[k];
  }
}

// Backward: v_i = S_i^-1 y_i - P_n^T v_n, in place, over one lane's nodes in descending order.
ENAMEL_CPU_CLONES void sweepBackward(const RodDampingSolve& f, const std::vector<int>& nodes, VecX& v) {
  for (auto it = nodes.rbegin(); it != nodes.rend(); ++it) {
    const int node = *it, n = f.after[node];
    double* x = v.data() + 6 * node;
    const RodDampingSolve::GroupFactors& F = f.groupFactors[f.factorsOf[node]];
    Quad x0 = times(F.Sinv[0], x, 0), x1 = times(F.Sinv[1], x, 1);
    if (n >= 0) {
      const RodDampingSolve::GroupFactors& Fn = f.groupFactors[f.factorsOf[n]];
      x0 -= times(Fn.PT[0], v.data() + 6 * n, 0), x1 -= times(Fn.PT[1], v.data() + 6 * n, 1);
    }
    for (int k = 0; k < 3; ++k) x[kGroups[0][k]] = x0[k], x[kGroups[1][k]] = x1[k];
  }
}

}  // namespace

void solveRodDamping(const RodDampingSolve& f, const VecX& vStar, VecX& v) {
  const int lanes = static_cast<int>(f.lanes.size());
#pragma omp parallel for schedule(static, 1)
  for (int lane = 0; lane < lanes; ++lane) {
    const FlushSubnormals flush;
    sweepForward(f, f.lanes[lane], vStar, v);
    sweepBackward(f, f.lanes[lane], v);
  }
}

RodDampingSolve factoriseRodDamping(const SpMat& K, const VecX& mass, const std::vector<int>& prescribedDofs,
                                    const std::vector<int>& nodeRod, double scale, double c) {
  RodDampingSolve f;
  f.scale = scale, f.c = c;
  const int nodes = static_cast<int>(mass.size() / 6);
  f.before.assign(nodes, -1), f.after.assign(nodes, -1), f.factorsOf.assign(nodes, -1);
  f.diag.assign(nodes, std::array<double, 6>{});
  const std::vector<char> prescribed = prescribedMask(static_cast<int>(mass.size()), prescribedDofs);
  factoriseNodes(K, mass, prescribed, f, [](int, bool, bool) { return true; });
  splitFactorsByGroups(f);
  f.rhsScale = scale * mass;
  for (int dof : prescribedDofs) f.rhsScale[dof] = 1;
  collectGripCouplings(K, prescribedDofs, prescribed, f);
  // lanes: contiguous ranges of rod numbers
  const int rods = nodeRod.empty() ? 1 : *std::max_element(nodeRod.begin(), nodeRod.end()) + 1;
  const int lanes = std::max(1, std::min(RodDampingSolve::kLanes, rods));
  f.lanes.assign(lanes, {});
  for (int node = 0; node < nodes; ++node)
    f.lanes[static_cast<long>(nodeRod[node]) * lanes / rods].push_back(node);
  return f;
}

long refactoriseRodDamping(const SpMat& K, const VecX& mass, const std::vector<int>& prescribedDofs,
                           RodDampingSolve& f) {
  const std::vector<char> prescribed = prescribedMask(static_cast<int>(mass.size()), prescribedDofs);
  const long count = factoriseNodes(K, mass, prescribed, f,
                                    [](int, bool changed, bool beforeRedone) { return changed || beforeRedone; });
  splitFactorsByGroups(f);
  collectGripCouplings(K, prescribedDofs, prescribed, f);
  return count;
}

void multiplyGripRows(const RodDampingSolve& f, const VecX& v, VecX& Kv) {
  const int grips = static_cast<int>(f.gripRowStart.size()) - 1;
  Kv.resize(grips);
  for (int i = 0; i < grips; ++i) {
    double sum = 0;
    for (int e = f.gripRowStart[i]; e < f.gripRowStart[i + 1]; ++e) sum += f.gripRowK[e] * v[f.gripRowDof[e]];
    Kv[i] = sum;
  }
}

}  // namespace enamel
