#pragma once
// Stiffnesses in 6 x 6 node blocks, for the lumped step's per-node rows (integrators.cpp): the rods' K and the
// elastic interfaces' (kernels.hpp elasticInterfaceBlocks); each distinct block stored once, and where a
// stiffness never couples two groups of a node's DOFs (DofGroups) only the 18 entries that can be non-zero.
// Plain data and inline loops; no I/O.
#include <Eigen/Dense>
#include <Eigen/Sparse>
#include <array>
#include <functional>
#include <utility>
#include <vector>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace enamel {

using SpMatRow = Eigen::SparseMatrix<double, Eigen::RowMajor>;

// K in 6 x 6 node blocks (block compressed rows): one column index per block instead of one per entry, and
// the six rows of a node summed side by side. The beam stiffness is assembled from whole 12 x 12 element
// matrices, so every stored block is full; and since every element of a ply has the same matrix, the blocks
// take only a handful of distinct values (10 in the bench's cases), kept once each: the product reads two
// integers per block instead of 36 doubles.
using Vec6 = Eigen::Matrix<double, 6, 1>;
// Two doubles side by side (GCC/Clang vector extension: one SSE2 register): the lumped step's paired loops.
typedef double DoublePair __attribute__((vector_size(16)));
using Mat6 = Eigen::Matrix<double, 6, 6>;  // column-major, as the blocks are stored

// The two groups of three DOFs of a node (ux uy uz rx ry rz = 0..5) that a stiffness never couples, each in
// ascending order: rods that lie in xy-planes never couple (ux, uy, rz) with (uz, rx, ry); an in-slice
// interface (normal and arms in a yz-plane) never couples (ux, ry, rz) with (uy, uz, rx).
struct DofGroups {
  int first[3], second[3];
  constexpr bool inFirst(int dof) const { return dof == first[0] || dof == first[1] || dof == first[2]; }
  // the column that row `row` multiplies at the k-th of its three products: its own group's k-th DOF
  constexpr int column(int row, int k) const { return inFirst(row) ? first[k] : second[k]; }
};
inline constexpr DofGroups kRodGroups{{0, 1, 5}, {2, 3, 4}};
inline constexpr DofGroups kInterfaceGroups{{0, 4, 5}, {1, 2, 3}};

struct NodeBlockMatrix {
  int blockRows = 0;
  std::vector<int> start;      // block row R holds blocks start[R] .. start[R + 1] - 1
  std::vector<int> column;     // block column of each block
  std::vector<int> valueOf;    // each block's entry in `values`
  std::vector<double> values;  // distinct blocks, column-major: block v, entry (i, j) at values[36 v + 6 j + i]
  // When every block is zero between the two DOF groups `groups`: the 18 entries that can be non-zero, per
  // distinct block, in the order of the product's pairs (multiplyBlockRowGroups), as 9 aligned pairs; empty
  // otherwise. splitAt: each block's first pair in `split` (9 x valueOf).
  std::vector<DoublePair> split;
  std::vector<int> splitAt;
};

// One block row: (block column, 6 x 6 block column-major) in ascending column order.
using BlockRow = std::vector<std::pair<int, std::array<double, 36>>>;

// The 18 entries of each distinct block that can be non-zero, in multiplyBlockRowGroups's order (the layout:
// node_blocks.cpp); empty when some block couples the two groups.
std::vector<DoublePair> splitBlocks(const std::vector<double>& values, const DofGroups& groups);

// K (row-major, whole 6 x 6 blocks on node boundaries) in node blocks, with `split` filled when K does not
// couple the two groups. Throws SolverError when K is not made of whole node blocks.
NodeBlockMatrix toNodeBlocks(const SpMatRow& K, const DofGroups& groups = kRodGroups);
// The same from block rows given one at a time (rows(R, row) fills block row R, ascending columns); blocks
// that agree to `tolerance` relative to their largest entry (within a binade) share the first one's values
// (0: only blocks equal bit for bit).
NodeBlockMatrix toNodeBlocks(int blockRows, const std::function<void(int, BlockRow&)>& rows, const DofGroups& groups,
                             double tolerance = 0);

// Block row R of K times x1 and x2, (K x1)_R and (K x2)_R, in one pass over the row (the matrix is read once
// for both products). Each row sums its entries in ascending column order, as a compressed-row product
// would, so the result is the same bit for bit, whichever thread computes it.
inline void multiplyBlockRow(const NodeBlockMatrix& K, int R, const double* x1, const double* x2, Vec6& y1, Vec6& y2) {
  Vec6 s1 = Vec6::Zero(), s2 = Vec6::Zero();
  for (int b = K.start[R]; b < K.start[R + 1]; ++b) {
    const Eigen::Map<const Mat6> block(K.values.data() + 36 * static_cast<std::size_t>(K.valueOf[b]));
    const double* a1 = x1 + 6 * K.column[b];
    const double* a2 = x2 + 6 * K.column[b];
    for (int j = 0; j < 6; ++j) {
      s1 += block.col(j) * a1[j];
      s2 += block.col(j) * a2[j];
    }
  }
  y1 = s1;
  y2 = s2;
}

namespace detail {
// (x0, x0) and (x1, x1) of a pair (x0, x1): one SSE2 shuffle each where there is SSE2
inline DoublePair lowOf(DoublePair a) {
#if defined(__SSE2__)
  return reinterpret_cast<DoublePair>(_mm_shuffle_epi32(reinterpret_cast<__m128i>(a), 0x44));
#else
  return DoublePair{a[0], a[0]};
#endif
}
inline DoublePair highOf(DoublePair a) {
#if defined(__SSE2__)
  return reinterpret_cast<DoublePair>(_mm_shuffle_epi32(reinterpret_cast<__m128i>(a), 0xEE));
#else
  return DoublePair{a[1], a[1]};
#endif
}

// (a_c0, a_c1) of a node's six values a (three aligned pairs): the stored pair, a broadcast, or two picked.
template <int c0, int c1>
[[gnu::always_inline]] inline DoublePair pick(const DoublePair* a) {
  if constexpr (c0 == c1) return c0 % 2 == 0 ? lowOf(a[c0 / 2]) : highOf(a[c0 / 2]);
  else if constexpr (c0 % 2 == 0 && c1 == c0 + 1) return a[c0 / 2];
  else return DoublePair{a[c0 / 2][c0 % 2], a[c1 / 2][c1 % 2]};
}

// s += one block's 18 entries B (9 pairs) times the node's six values a (three aligned pairs), rows paired
// (0, 1), (2, 3), (4, 5): at the k-th product (k = 0, 1, 2) row r multiplies column G.column(r, k), so each row
// adds its products in ascending column order.
template <const DofGroups& G, int k, int p>
[[gnu::always_inline]] inline void addPairProduct(const DoublePair* B, const DoublePair* a, DoublePair* s) {
  s[p] += B[3 * k + p] * pick<G.column(2 * p, k), G.column(2 * p + 1, k)>(a);
}
template <const DofGroups& G>
[[gnu::always_inline]] inline void addSplitBlock(const DoublePair* B, const DoublePair* a, DoublePair* s) {
  addPairProduct<G, 0, 0>(B, a, s), addPairProduct<G, 0, 1>(B, a, s), addPairProduct<G, 0, 2>(B, a, s);
  addPairProduct<G, 1, 0>(B, a, s), addPairProduct<G, 1, 1>(B, a, s), addPairProduct<G, 1, 2>(B, a, s);
  addPairProduct<G, 2, 0>(B, a, s), addPairProduct<G, 2, 1>(B, a, s), addPairProduct<G, 2, 2>(B, a, s);
}
}  // namespace detail

// Block row R of K times x for blocks that do not couple the groups G (K.split not empty, built for G), into
// pairs (y[0] = rows 0-1, y[1] = rows 2-3, y[2] = rows 4-5): the 18 entries that can be non-zero instead of
// 36, three pairs of rows at a time; x 16-byte aligned (Eigen's vectors are). Every row adds the same products
// in the same (ascending column) order as multiplyBlockRow, and the products it leaves out are exact zeros, so
// the result is multiplyBlockRow's (up to the sign of a zero). Three accumulators and a block's pairs stay in
// the 16 SSE2 registers.
template <const DofGroups& G>
[[gnu::always_inline]] inline void multiplyBlockRowGroups(const NodeBlockMatrix& K, int R, const double* x,
                                                          DoublePair* y) {
  const DoublePair* split = K.split.data();
  const DoublePair* a = static_cast<const DoublePair*>(__builtin_assume_aligned(x, 16));
  DoublePair s[3] = {{0, 0}, {0, 0}, {0, 0}};
  for (int b = K.start[R]; b < K.start[R + 1]; ++b) detail::addSplitBlock<G>(split + K.splitAt[b], a + 3 * K.column[b], s);
  y[0] = s[0], y[1] = s[1], y[2] = s[2];
}

// The rods' K (groups kRodGroups) times x1 and x2, one vector at a time.
inline void multiplyBlockRowSplitPairs(const NodeBlockMatrix& K, int R, const double* x1, const double* x2,
                                       DoublePair* y1, DoublePair* y2) {
  multiplyBlockRowGroups<kRodGroups>(K, R, x1, y1);
  multiplyBlockRowGroups<kRodGroups>(K, R, x2, y2);
}

// multiplyBlockRowGroups<G> into a 6-vector.
template <const DofGroups& G>
inline void multiplyBlockRowSplit(const NodeBlockMatrix& K, int R, const double* x, Vec6& y) {
  DoublePair p[3];
  multiplyBlockRowGroups<G>(K, R, x, p);
  y << p[0][0], p[0][1], p[1][0], p[1][1], p[2][0], p[2][1];
}

}  // namespace enamel
