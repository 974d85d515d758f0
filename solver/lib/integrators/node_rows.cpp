// The lumped step's node rows (node_rows.hpp), in a unit of their own: compiled three times where GCC builds for
// x86-64 (function multi-versioning), and the loader picks the one the CPU runs: x86-64-v4 (AVX-512: 32 vector
// registers, broadcasts folded into the multiply-adds), x86-64-v3 (AVX2, FMA) or the default x86-64. The v4 and v3
// copies give the same bits; the default differs from them by round-off (FMA rounds a * b + c once); one CPU gives
// the same bits at any thread count.
#include "integrators/node_rows.hpp"

#include <array>
#include <map>

namespace enamel {

#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
#define ENAMEL_HAS_CPU_CLONES 1
#define ENAMEL_CPU_CLONES [[gnu::target_clones("arch=x86-64-v4", "arch=x86-64-v3", "default")]]
#else
#define ENAMEL_HAS_CPU_CLONES 0
#define ENAMEL_CPU_CLONES
#endif

namespace {

// One node's v_{n+1/2} into vTo from its block rows of K times q and v (= v_{n-1/2}), K_I q (KIq), and
// the wrench of its interfaces beyond their elastic force W (f_iface = K_I q - W, so r = K q + K_I q - W + b' K v),
// and its q_{n+1} = q_n + dt v_{n+1/2} into qTo
// (the grips' q is prescribed afterwards); the sums v.Mv and v.Kv (even and odd DOFs side by side), max |dt v|
// and max |q_{n+1}|. r and the free DOFs' v two at a time (the same operations per DOF); then the grips.
[[gnu::always_inline]] inline void advanceNode(NodeRows& rows, const Operators& ops, const NodeStep& c, int node,
                                               const double* q, const double* v, const double* W,
                                               const DoublePair* KIq, double* vTo, double* qTo, SliceSums& sums) {
  using Pair = DoublePair;
  const NodeBlockMatrix& K = rows.K;
  Pair Kq[3], Kv[3];
  if (!K.split.empty() && c.b == 0) {  // the rods' damping is taken after the pass (rod_damping implicit): K q only
    multiplyBlockRowGroups<kRodGroups>(K, node, q, Kq);
    for (int j = 0; j < 3; ++j) Kv[j] = Pair{0, 0};
  } else if (!K.split.empty()) {
    multiplyBlockRowSplitPairs(K, node, q, v, Kq, Kv);
  } else {
    Vec6 a, b;
    multiplyBlockRow(K, node, q, v, a, b);
    for (int j = 0; j < 3; ++j) Kq[j] = Pair{a[2 * j], a[2 * j + 1]}, Kv[j] = Pair{b[2 * j], b[2 * j + 1]};
  }
  auto pairs = [node](const double* x) { return static_cast<const Pair*>(__builtin_assume_aligned(x + 6 * node, 16)); };
  const NodeMass& nodeMass = rows.masses[rows.massOf[node]];
  const Pair *vNode = pairs(v), *invM = nodeMass.invMass, *mass = nodeMass.mass;
  const Pair* Wp = static_cast<const Pair*>(__builtin_assume_aligned(W, 16));
  Pair r[3], vn[3];
  for (int j = 0; j < 3; ++j) {
    r[j] = ((Kq[j] + KIq[j]) - Wp[j]) + Pair{c.b, c.b} * Kv[j];
    vn[j] = (Pair{c.keep, c.keep} * vNode[j] - Pair{c.dt, c.dt} * (invM[j] * r[j])) / Pair{c.scale, c.scale};
  }
  if (rows.nodeHasGrip[node])
    for (int j = 0; j < 6; ++j) {
      const int grip = rows.gripOfDof[6 * node + j];
      if (grip < 0) continue;
      vn[j / 2][j % 2] = ops.prescribedShape[grip] * c.Vgrip;
      rows.gripResidual[grip] = r[j / 2][j % 2];
    }
  auto absMax = [](Pair m, Pair a) {
    const Pair mag = magnitude(a);
    return mag > m ? mag : m;
  };
  Pair* vOut = static_cast<Pair*>(__builtin_assume_aligned(vTo, 16));
  Pair* qOut = static_cast<Pair*>(__builtin_assume_aligned(qTo, 16));
  const Pair* qNode = pairs(q);
  for (int j = 0; j < 3; ++j) {
    vOut[j] = vn[j];
    sums.workM += vn[j] * (mass[j] * vn[j]), sums.workK += vn[j] * Kv[j];
    const Pair stepj = Pair{c.move, c.move} * vn[j], y = qNode[j] + stepj;
    qOut[j] = y;
    sums.largestStep = absMax(sums.largestStep, stepj), sums.largestValue = absMax(sums.largestValue, y);
  }
}

}  // namespace

// advanceNodesOfSlice (node_rows.hpp): K_I q_n for every node of slice k into KIq (three pairs per node, from the
// slice's first), then advanceNode for every node, W the wrench of its interfaces (node n's at
// W + stride (n - first node of the slice); stride 0: one wrench for all), v_{n+1/2} and q_{n+1} to vOut and qOut
// (the slice's nodes in order, from its first).
// K_I q_n has a loop of its own: a node's row is one chain of ~21 dependent multiply-adds, and the CPU overlaps
// the chains of several nodes only when nothing else stands between them in the instruction stream (with
// advanceNode's ~250 instructions between them, the nodes pass took 1.17x as long on the paper preset).
// Where the CPU has AVX-512, K_I q by multiplyInterfaceRowsAvx512 (node_blocks.hpp: the same bits). Compiled
// for three CPUs (target_clones), the loader picks one: x86-64-v4 (AVX-512), x86-64-v3 (AVX2, FMA: a * b + c
// in one rounding where the code has one multiply and one add) where the CPU has them, else the default x86-64.
ENAMEL_CPU_CLONES [[gnu::flatten]] SliceSums advanceNodesOfSlice(
    NodeRows& rows, const Operators& ops, const NodeStep& c, int k, const double* q, const double* v, const double* W,
    int stride, DoublePair* KIq, double* vOut, double* qOut) {
  SliceSums sums;
  const int firstNode = ops.sliceNodeStart[k];
  const int lastNode = ops.sliceNodeStart[k + 1];
  if (!rows.KIocts.empty())
    multiplyInterfaceRowsAvx512(rows.KI, rows.KIocts, firstNode, lastNode, q, KIq);
  else
    for (int node = firstNode; node < lastNode; ++node)
      multiplyBlockRowGroups<kInterfaceGroups>(rows.KI, node, q, KIq + 3 * (node - firstNode));
  for (int node = firstNode; node < lastNode; ++node)
    advanceNode(rows, ops, c, node, q, v, W + stride * (node - firstNode), KIq + 3 * (node - firstNode),
                vOut + 6 * (node - firstNode), qOut + 6 * (node - firstNode), sums);
  return sums;
}

void classifyNodeMasses(const VecX& mass, const VecX& invMass, int nodes, NodeRows& rows) {
  std::map<std::array<double, 12>, int> index;
  rows.massOf.resize(nodes);
  rows.masses.clear();
  for (int node = 0; node < nodes; ++node) {
    std::array<double, 12> key;
    for (int i = 0; i < 6; ++i) key[i] = mass[6 * node + i], key[6 + i] = invMass[6 * node + i];
    const auto [it, added] = index.emplace(key, static_cast<int>(rows.masses.size()));
    if (added) {
      NodeMass nm;
      for (int j = 0; j < 3; ++j)
        nm.mass[j] = DoublePair{key[2 * j], key[2 * j + 1]}, nm.invMass[j] = DoublePair{key[6 + 2 * j], key[7 + 2 * j]};
      rows.masses.push_back(nm);
    }
    rows.massOf[node] = it->second;
  }
}

std::string nodeRowsTarget(const NodeRows& rows) {
#if ENAMEL_HAS_CPU_CLONES
  if (cpuHasAvx512())
    return rows.KIocts.empty() ? "for x86-64-v4 (AVX-512)"
                           : "for x86-64-v4 (AVX-512; K_I rows on 8 doubles side by side)";
  if (__builtin_cpu_supports("x86-64-v3")) return "for x86-64-v3 (AVX2, FMA)";
#endif
  return "for x86-64 (this CPU has no AVX2 and FMA)";
}

}  // namespace enamel
