#pragma once
// The beam stiffness K in 6 x 6 node blocks, for the lumped step's per-node K rows (integrators.cpp): each
// distinct block stored once, and for rods that lie in xy-planes only the 18 entries that can be non-zero.
// Plain data and inline loops; no I/O.
#include <Eigen/Dense>
#include <Eigen/Sparse>
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

struct NodeBlockMatrix {
  int blockRows = 0;
  std::vector<int> start;      // block row R holds blocks start[R] .. start[R + 1] - 1
  std::vector<int> column;     // block column of each block
  std::vector<int> valueOf;    // each block's entry in `values`
  std::vector<double> values;  // distinct blocks, column-major: block v, entry (i, j) at values[36 v + 6 j + i]
  // When every block is zero between the in-plane DOFs (ux, uy, rz) and the out-of-plane ones (uz, rx, ry), as
  // for rods that lie in xy-planes: the 18 entries that can be non-zero, per distinct block, in the order of
  // the product's pairs (multiplyBlockRowSplit), as 9 aligned pairs; empty otherwise. splitAt: each block's
  // first pair in `split` (9 x valueOf).
  std::vector<DoublePair> split;
  std::vector<int> splitAt;
};

// The two DOF groups of a node that an in-plane rod's stiffness never couples, each in ascending order.
constexpr int kInPlaneDofs[3] = {0, 1, 5}, kOutOfPlaneDofs[3] = {2, 3, 4};

// The 18 entries of each distinct block that can be non-zero, in multiplyBlockRowSplit's order (the layout:
// node_blocks.cpp); empty when some block couples the in-plane and out-of-plane DOFs.
std::vector<DoublePair> splitBlocks(const std::vector<double>& values);

// K (row-major, whole 6 x 6 blocks on node boundaries) in node blocks, with `split` filled when it applies.
// Throws SolverError when K is not made of whole node blocks.
NodeBlockMatrix toNodeBlocks(const SpMatRow& K);

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

// s += one block's 18 entries B (9 pairs) times the node's six values a (three aligned pairs), rows paired
// (0, 1), (2, 3), (4, 5): for k = 0, 1, 2 the in-plane column i = kInPlaneDofs[k] and the out-of-plane column
// o = kOutOfPlaneDofs[k], so each row adds its products in ascending column order.
[[gnu::always_inline]] inline void addSplitBlock(const DoublePair* B, const DoublePair* a, DoublePair* s) {
  const DoublePair a01 = a[0], a23 = a[1], a45 = a[2];
  s[0] += B[0] * lowOf(a01), s[1] += B[1] * lowOf(a23), s[2] += B[2] * DoublePair{a23[0], a01[0]};
  s[0] += B[3] * highOf(a01), s[1] += B[4] * highOf(a23), s[2] += B[5] * DoublePair{a23[1], a01[1]};
  s[0] += B[6] * highOf(a45), s[1] += B[7] * lowOf(a45), s[2] += B[8] * a45;
}
}  // namespace detail

// multiplyBlockRow for blocks that do not couple the in-plane and out-of-plane DOFs (K.split not empty), into
// pairs (y[0] = rows 0-1, y[1] = rows 2-3, y[2] = rows 4-5): the 18 entries that can be non-zero instead of
// 36, three pairs of rows at a time, rows (4, 5) paired across the groups; x1 and x2 16-byte aligned (Eigen's
// vectors are). Every row adds the same products in the same (ascending column) order as multiplyBlockRow,
// and the products it leaves out are exact zeros, so the result is multiplyBlockRow's (up to the sign of a
// zero). One vector at a time: three accumulators and a block's pairs stay in the 16 SSE2 registers.
inline void multiplyBlockRowSplitPairs(const NodeBlockMatrix& K, int R, const double* x1, const double* x2,
                                       DoublePair* y1, DoublePair* y2) {
  using Pair = DoublePair;
  const Pair* split = K.split.data();
  auto product = [&](const double* x, Pair* y) {
    const Pair* a = static_cast<const Pair*>(__builtin_assume_aligned(x, 16));
    Pair s[3] = {{0, 0}, {0, 0}, {0, 0}};
    for (int b = K.start[R]; b < K.start[R + 1]; ++b) detail::addSplitBlock(split + K.splitAt[b], a + 3 * K.column[b], s);
    y[0] = s[0], y[1] = s[1], y[2] = s[2];
  };
  product(x1, y1);
  product(x2, y2);
}

// multiplyBlockRowSplitPairs into 6-vectors.
inline void multiplyBlockRowSplit(const NodeBlockMatrix& K, int R, const double* x1, const double* x2, Vec6& y1,
                                  Vec6& y2) {
  DoublePair p1[3], p2[3];
  multiplyBlockRowSplitPairs(K, R, x1, x2, p1, p2);
  y1 << p1[0][0], p1[0][1], p1[1][0], p1[1][1], p1[2][0], p1[2][1];
  y2 << p2[0][0], p2[0][1], p2[1][0], p2[1][1], p2[2][0], p2[2][1];
}

}  // namespace enamel
