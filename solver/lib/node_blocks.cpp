#include "node_blocks.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <string>
#include <unordered_map>

#include "errors.hpp"

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
