#pragma once
// Stiffnesses in 6 x 6 node blocks, for the lumped step's per-node rows (integrators/node_rows.cpp): the rods' K
// and the elastic interfaces' (kernels.hpp elasticInterfaceBlocks); each distinct block stored once, and where a
// stiffness never couples two groups of a node's DOFs (DofGroups) only the 18 entries that can be non-zero.
// Plain data and inline loops; no I/O.
#include <Eigen/Dense>
#include <Eigen/Sparse>
#include <array>
#include <functional>
#include <utility>
#include <vector>

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
// |a| of both doubles: the sign bits cleared (one instruction; -0 gives +0).
inline DoublePair magnitude(DoublePair a) {
  typedef long long Bits __attribute__((vector_size(16)));
  return reinterpret_cast<DoublePair>(reinterpret_cast<Bits>(a) & Bits{0x7fffffffffffffffLL, 0x7fffffffffffffffLL});
}
// Four doubles side by side (one AVX register where the code is compiled for AVX, two SSE2 registers elsewhere):
// a column of a 3 x 3 group block, padded with a zero.
typedef double DoubleQuad __attribute__((vector_size(32)));
// A quad as the element of a std::vector: alignas makes the allocation 32-byte aligned (aligned new), which a
// vector type as a template argument does not guarantee.
struct alignas(32) StoredQuad {
  DoubleQuad q;
};
using Mat6 = Eigen::Matrix<double, 6, 6>;  // column-major, as the blocks are stored

// The two groups of three DOFs of a node (ux uy uz rx ry rz = 0..5) that a stiffness never couples, each in
// ascending order: rods that lie in xy-planes never couple (ux, uy, rz) with (uz, rx, ry); an in-slice
// interface (normal and arms in a yz-plane) never couples (ux, ry, rz) with (uy, uz, rx).
struct DofGroups {
  int first[3], second[3];
  constexpr bool inFirst(int dof) const { return dof == first[0] || dof == first[1] || dof == first[2]; }
  // where row `row` stands in its group (0, 1, 2)
  constexpr int laneOf(int row) const {
    const int* g = inFirst(row) ? first : second;
    return row == g[0] ? 0 : row == g[1] ? 1 : 2;
  }
};
inline constexpr DofGroups kRodGroups{{0, 1, 5}, {2, 3, 4}};
inline constexpr DofGroups kInterfaceGroups{{0, 4, 5}, {1, 2, 3}};

struct NodeBlockMatrix {
  int blockRows = 0;
  std::vector<int> start;      // block row R holds blocks start[R] .. start[R + 1] - 1
  std::vector<int> column;     // block column of each block
  std::vector<int> valueOf;    // each block's entry in `values`
  std::vector<double> values;  // distinct blocks, column-major: block v, entry (i, j) at values[36 v + 6 j + i]
  // When every block is zero between the two DOF groups `groups`: per distinct block, the 18 entries that can be
  // non-zero as its two 3 x 3 group blocks, column by column, each column a quad padded with a zero: for the
  // group g = groups.first, then groups.second, and k = 0, 1, 2 the quad (B(g0, gk), B(g1, gk), B(g2, gk), 0).
  // Block v's six quads start at split[6 v]. Empty otherwise.
  std::vector<StoredQuad> split;
  // With split: each block's first quad in split (6 valueOf) and the first DOF of its block column (6 column),
  // side by side, so that the products' loops read one pair per block and compute no index.
  struct SplitRef {
    int quad, dof;
  };
  std::vector<SplitRef> splitRef;
};

// One block row: (block column, 6 x 6 block column-major) in ascending column order.
using BlockRow = std::vector<std::pair<int, std::array<double, 36>>>;

// The 18 entries of each distinct block that can be non-zero, as NodeBlockMatrix::split lays them out; empty when
// some block couples the two groups.
std::vector<StoredQuad> splitBlocks(const std::vector<double>& values, const DofGroups& groups);

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
// s1 += group G.first's 3 x 3 block times the node's values a at G.first's DOFs, s2 the same for G.second; B the
// block's six quads (NodeBlockMatrix::split), column k = 0, 1, 2 in turn: each row adds its products in ascending
// column order. The padding lane adds zeros.
template <const DofGroups& G>
[[gnu::always_inline]] inline void addGroupBlocks(const DoubleQuad* B, const double* a, DoubleQuad& s1, DoubleQuad& s2) {
  s1 += B[0] * a[G.first[0]], s2 += B[3] * a[G.second[0]];
  s1 += B[1] * a[G.first[1]], s2 += B[4] * a[G.second[1]];
  s1 += B[2] * a[G.first[2]], s2 += B[5] * a[G.second[2]];
}

// row `row` of a product held by group (s1: G.first's rows, s2: G.second's)
template <const DofGroups& G, int row>
[[gnu::always_inline]] inline double rowOf(const DoubleQuad& s1, const DoubleQuad& s2) {
  if constexpr (G.inFirst(row)) return s1[G.laneOf(row)];
  else return s2[G.laneOf(row)];
}
// the product by group into pairs of rows (0, 1), (2, 3), (4, 5)
template <const DofGroups& G>
[[gnu::always_inline]] inline void toPairs(const DoubleQuad& s1, const DoubleQuad& s2, DoublePair* y) {
  y[0] = DoublePair{rowOf<G, 0>(s1, s2), rowOf<G, 1>(s1, s2)};
  y[1] = DoublePair{rowOf<G, 2>(s1, s2), rowOf<G, 3>(s1, s2)};
  y[2] = DoublePair{rowOf<G, 4>(s1, s2), rowOf<G, 5>(s1, s2)};
}
}  // namespace detail

// Block row R of K times x for blocks that do not couple the groups G (K.split not empty, built for G), into
// pairs (y[0] = rows 0-1, y[1] = rows 2-3, y[2] = rows 4-5): the 18 entries that can be non-zero instead of
// 36, each group's three rows at a time. Every row adds the same products in the same (ascending column) order
// as multiplyBlockRow, and the products it leaves out are exact zeros, so the result is multiplyBlockRow's (up
// to the sign of a zero).
template <const DofGroups& G>
[[gnu::always_inline]] inline void multiplyBlockRowGroups(const NodeBlockMatrix& K, int R, const double* x,
                                                          DoublePair* y) {
  const DoubleQuad* split = &K.split.data()->q;
  const NodeBlockMatrix::SplitRef* ref = K.splitRef.data();
  DoubleQuad s1 = {}, s2 = {};
  for (int b = K.start[R]; b < K.start[R + 1]; ++b) detail::addGroupBlocks<G>(split + ref[b].quad, x + ref[b].dof, s1, s2);
  detail::toPairs<G>(s1, s2, y);
}

// The rods' K (groups kRodGroups) times x1 and x2 in one pass over the row: each product as
// multiplyBlockRowGroups's, bit for bit; the four sums side by side give the CPU four chains of additions.
inline void multiplyBlockRowSplitPairs(const NodeBlockMatrix& K, int R, const double* x1, const double* x2,
                                       DoublePair* y1, DoublePair* y2) {
  const DoubleQuad* split = &K.split.data()->q;
  const NodeBlockMatrix::SplitRef* ref = K.splitRef.data();
  DoubleQuad s1 = {}, s2 = {}, t1 = {}, t2 = {};
  for (int b = K.start[R]; b < K.start[R + 1]; ++b) {
    const DoubleQuad* B = split + ref[b].quad;
    const int c = ref[b].dof;
    detail::addGroupBlocks<kRodGroups>(B, x1 + c, s1, s2);
    detail::addGroupBlocks<kRodGroups>(B, x2 + c, t1, t2);
  }
  detail::toPairs<kRodGroups>(s1, s2, y1);
  detail::toPairs<kRodGroups>(t1, t2, y2);
}

// A distinct block's two 3 x 3 group blocks side by side, for CPUs with AVX-512 (one 512-bit register per column):
// column k of the first group's block in lanes 0-3 and of the second group's in lanes 4-7 (the quads 6 v + k and
// 6 v + 3 + k of NodeBlockMatrix::split), so block v's three octs start at octs[3 v].
struct alignas(64) StoredOct {
  double lane[8];
};
std::vector<StoredOct> octsOfSplit(const std::vector<StoredQuad>& split);

// Whether this CPU runs x86-64-v4 code (AVX-512 F, BW, CD, DQ, VL); false where this build has no such code.
bool cpuHasAvx512();

// multiplyBlockRowGroups<kInterfaceGroups> of rows first .. last - 1 into y (three pairs per row, the first row's
// first), K's blocks read as octs (octsOfSplit(K.split)): a block is one load of the column node's six values,
// three permutes and three multiply-adds instead of six broadcasts and six multiply-adds, two rows' blocks in
// turn. Every lane adds the same products in the same order as multiplyBlockRowGroups built for x86-64-v3 (FMA),
// so the result is that build's bit for bit. Compiled for x86-64-v4 only: call it only where cpuHasAvx512().
void multiplyInterfaceRowsAvx512(const NodeBlockMatrix& K, const std::vector<StoredOct>& octs, int first, int last,
                                 const double* x, DoublePair* y);

// multiplyBlockRowGroups<G> into a 6-vector.
template <const DofGroups& G>
inline void multiplyBlockRowSplit(const NodeBlockMatrix& K, int R, const double* x, Vec6& y) {
  DoublePair p[3];
  multiplyBlockRowGroups<G>(K, R, x, p);
  y << p[0][0], p[0][1], p[1][0], p[1][1], p[2][0], p[2][1];
}

}  // namespace enamel
