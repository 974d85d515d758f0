#include "kernels/node_blocks.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <string>
#include <unordered_map>

// AVX-512 rows where GCC builds for x86-64 (as the node rows' clones, integrators/node_rows.cpp)
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
#include <immintrin.h>
#define ENAMEL_HAS_AVX512_ROWS 1
#else
#define ENAMEL_HAS_AVX512_ROWS 0
#endif

#include "base/errors.hpp"

namespace enamel {

// split's layout (NodeBlockMatrix::split): per block, group first then second, column k = 0, 1, 2 of the group's
// 3 x 3 block padded with a zero. Empty when some block couples the groups.
std::vector<StoredQuad> splitBlocks(const std::vector<double>& values, const DofGroups& groups) {
  std::vector<StoredQuad> split;
  for (std::size_t v = 0; 36 * v < values.size(); ++v) {
    auto B = [&](int i, int j) { return values[36 * v + 6 * j + i]; };
    for (int i : groups.first)
      for (int j : groups.second)
        if (B(i, j) != 0.0 || B(j, i) != 0.0) return {};
    for (const int* g : {groups.first, groups.second})
      for (int k = 0; k < 3; ++k) split.push_back({DoubleQuad{B(g[0], g[k]), B(g[1], g[k]), B(g[2], g[k]), 0.0}});
  }
  return split;
}

std::vector<StoredOct> octsOfSplit(const std::vector<StoredQuad>& split) {
  std::vector<StoredOct> octs(split.size() / 2);
  for (std::size_t v = 0; 6 * v < split.size(); ++v)
    for (int k = 0; k < 3; ++k)
      for (int i = 0; i < 4; ++i) {
        octs[3 * v + k].lane[i] = split[6 * v + k].q[i];
        octs[3 * v + k].lane[4 + i] = split[6 * v + 3 + k].q[i];
      }
  return octs;
}

#if ENAMEL_HAS_AVX512_ROWS
bool cpuHasAvx512() { return __builtin_cpu_supports("x86-64-v4"); }

namespace {
// The octs' products for groups G (x86-64-v4 only). Lane l < 4 of a row's sum is multiplyBlockRowGroups's s1[l],
// lane 4 + l its s2[l]: per block, column k = 0, 1, 2 in turn, B(., k) times the column node's value at
// G.first[k] (lanes 0-3) and G.second[k] (lanes 4-7), one rounding per multiply-add.
template <const DofGroups& G>
struct OctRows {
  __m512i column[3];  // permute indices: value G.first[k] to lanes 0-3, G.second[k] to lanes 4-7
  __m512i rows;       // the sum's lanes in row order 0..5 (DofGroups::laneOf, + 4 in the second group)
  [[gnu::target("arch=x86-64-v4")]] OctRows() {
    for (int k = 0; k < 3; ++k)
      column[k] = _mm512_set_epi64(G.second[k], G.second[k], G.second[k], G.second[k], G.first[k], G.first[k],
                                   G.first[k], G.first[k]);
    auto lane = [](int row) { return G.inFirst(row) ? G.laneOf(row) : 4 + G.laneOf(row); };
    rows = _mm512_set_epi64(0, 0, lane(5), lane(4), lane(3), lane(2), lane(1), lane(0));
  }
  [[gnu::target("arch=x86-64-v4"), gnu::always_inline]] inline __m512d add(const StoredOct* B, const double* a,
                                                                          __m512d sum) const {
    const __m512d values = _mm512_maskz_loadu_pd(0x3F, a);  // the node's six, no more
    sum = _mm512_fmadd_pd(_mm512_load_pd(B[0].lane), _mm512_permutexvar_pd(column[0], values), sum);
    sum = _mm512_fmadd_pd(_mm512_load_pd(B[1].lane), _mm512_permutexvar_pd(column[1], values), sum);
    return _mm512_fmadd_pd(_mm512_load_pd(B[2].lane), _mm512_permutexvar_pd(column[2], values), sum);
  }
  [[gnu::target("arch=x86-64-v4"), gnu::always_inline]] inline void store(__m512d sum, DoublePair* y) const {
    _mm512_mask_storeu_pd(reinterpret_cast<double*>(y), 0x3F, _mm512_permutexvar_pd(rows, sum));
  }
};

template <const DofGroups& G>
[[gnu::target("arch=x86-64-v4")]] void multiplyRowsOcts(const NodeBlockMatrix& K, const StoredOct* octs, int first,
                                                        int last, const double* x, DoublePair* y) {
  const OctRows<G> o;
  const NodeBlockMatrix::SplitRef* ref = K.splitRef.data();
  int R = first;
  for (; R + 1 < last; R += 2, y += 6) {  // two rows, their blocks in turn
    __m512d s = _mm512_setzero_pd(), t = _mm512_setzero_pd();
    int i = K.start[R], j = K.start[R + 1];
    const int iEnd = j, jEnd = K.start[R + 2];
    for (; i < iEnd && j < jEnd; ++i, ++j) {
      s = o.add(octs + ref[i].quad / 2, x + ref[i].dof, s);
      t = o.add(octs + ref[j].quad / 2, x + ref[j].dof, t);
    }
    for (; i < iEnd; ++i) s = o.add(octs + ref[i].quad / 2, x + ref[i].dof, s);
    for (; j < jEnd; ++j) t = o.add(octs + ref[j].quad / 2, x + ref[j].dof, t);
    o.store(s, y);
    o.store(t, y + 3);
  }
  if (R < last) {
    __m512d s = _mm512_setzero_pd();
    for (int i = K.start[R]; i < K.start[R + 1]; ++i) s = o.add(octs + ref[i].quad / 2, x + ref[i].dof, s);
    o.store(s, y);
  }
}
}  // namespace

void multiplyInterfaceRowsAvx512(const NodeBlockMatrix& K, const std::vector<StoredOct>& octs, int first, int last,
                                 const double* x, DoublePair* y) {
  multiplyRowsOcts<kInterfaceGroups>(K, octs.data(), first, last, x, y);
}
#else
bool cpuHasAvx512() { return false; }
void multiplyInterfaceRowsAvx512(const NodeBlockMatrix&, const std::vector<StoredOct>&, int, int, const double*,
                                 DoublePair*) {
  throw SolverError("multiplyInterfaceRowsAvx512: this build has no AVX-512 code");
}
#endif

namespace {
// Distinct blocks, kept once each: a block's 36 values -> its index in B.values. Exact (tolerance 0: bit for bit),
// or with a relative tolerance t: the values rounded to a multiple of t times the power of two at or above the
// block's largest |entry| (and that power) are the key, and the first block of a key stands for all of them.
struct DistinctBlocks {
  double tolerance = 0;
  std::unordered_map<std::string, int> index;
  std::string keyOf(const std::array<double, 36>& block) const {
    if (tolerance == 0) return std::string(reinterpret_cast<const char*>(block.data()), sizeof block);
    double largest = 0;
    for (double v : block) largest = std::max(largest, std::abs(v));
    int exponent = 0;
    std::frexp(largest, &exponent);
    const double quantum = tolerance * std::ldexp(1.0, exponent);
    std::array<long long, 37> key;
    key[36] = exponent;
    for (int e = 0; e < 36; ++e) key[e] = largest > 0 ? std::llround(block[e] / quantum) : 0;
    return std::string(reinterpret_cast<const char*>(key.data()), sizeof key);
  }
  void add(NodeBlockMatrix& B, int column, const std::array<double, 36>& block) {
    const auto [it, added] = index.emplace(keyOf(block), static_cast<int>(index.size()));
    if (added) B.values.insert(B.values.end(), block.begin(), block.end());
    B.column.push_back(column);
    B.valueOf.push_back(it->second);
  }
};

void finishSplit(NodeBlockMatrix& B, const DofGroups& groups) {
  B.split = splitBlocks(B.values, groups);
  if (B.split.empty()) return;
  B.splitRef.resize(B.column.size());
  for (std::size_t b = 0; b < B.column.size(); ++b) B.splitRef[b] = {6 * B.valueOf[b], 6 * B.column[b]};
}
}  // namespace

NodeBlockMatrix toNodeBlocks(const SpMatRow& K, const DofGroups& groups) {
  if (K.rows() % 6 != 0) throw SolverError("stiffness matrix: size not a multiple of 6");
  NodeBlockMatrix B;
  B.blockRows = static_cast<int>(K.rows() / 6);
  B.start.assign(1, 0);
  DistinctBlocks distinct;
  std::array<double, 36> block;
  for (int R = 0; R < B.blockRows; ++R) {
    const int first = static_cast<int>(K.outerIndexPtr()[6 * R]), count = K.outerIndexPtr()[6 * R + 1] - first;
    if (count % 6 != 0) throw SolverError("stiffness matrix: a row is not made of whole 6 x 6 blocks");
    for (int k = 0; k < count; k += 6) {
      const int c = K.innerIndexPtr()[first + k];
      if (c % 6 != 0) throw SolverError("stiffness matrix: a block does not start on a node");
      for (int j = 0; j < 6; ++j)
        for (int i = 0; i < 6; ++i) {
          const int row = 6 * R + i, at = K.outerIndexPtr()[row] + k + j;
          if (K.outerIndexPtr()[row + 1] - K.outerIndexPtr()[row] != count || K.innerIndexPtr()[at] != c + j)
            throw SolverError("stiffness matrix: the rows of a node do not share one block pattern");
          block[6 * j + i] = K.valuePtr()[at];
        }
      distinct.add(B, c / 6, block);
    }
    B.start.push_back(static_cast<int>(B.column.size()));
  }
  finishSplit(B, groups);
  return B;
}

NodeBlockMatrix toNodeBlocks(int blockRows, const std::function<void(int, BlockRow&)>& rows, const DofGroups& groups,
                             double tolerance) {
  NodeBlockMatrix B;
  B.blockRows = blockRows;
  B.start.assign(1, 0);
  DistinctBlocks distinct{tolerance, {}};
  BlockRow row;
  for (int R = 0; R < blockRows; ++R) {
    row.clear();
    rows(R, row);
    for (std::size_t b = 0; b < row.size(); ++b) {
      if (b > 0 && row[b].first <= row[b - 1].first) throw SolverError("node blocks: a row's columns are not ascending");
      distinct.add(B, row[b].first, row[b].second);
    }
    B.start.push_back(static_cast<int>(B.column.size()));
  }
  finishSplit(B, groups);
  return B;
}

}  // namespace enamel
