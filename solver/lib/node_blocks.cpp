#include "node_blocks.hpp"

#include <array>
#include <string>
#include <unordered_map>

#include "errors.hpp"

namespace enamel {

// split's layout: for k = 0, 1, 2 with column i = kInPlaneDofs[k] and column o = kOutOfPlaneDofs[k], the pairs
// (B(0, i), B(1, i)), (B(2, o), B(3, o)), (B(4, o), B(5, i)): rows 0-1 and 5 take the in-plane columns, rows
// 2-4 the out-of-plane ones, each in ascending column order. Empty when some block couples the groups.
std::vector<DoublePair> splitBlocks(const std::vector<double>& values) {
  std::vector<DoublePair> split;
  for (std::size_t v = 0; 36 * v < values.size(); ++v) {
    auto B = [&](int i, int j) { return values[36 * v + 6 * j + i]; };
    for (int i : kInPlaneDofs)
      for (int j : kOutOfPlaneDofs)
        if (B(i, j) != 0.0 || B(j, i) != 0.0) return {};
    for (int k = 0; k < 3; ++k) {
      const int i = kInPlaneDofs[k], o = kOutOfPlaneDofs[k];
      split.insert(split.end(), {DoublePair{B(0, i), B(1, i)}, DoublePair{B(2, o), B(3, o)}, DoublePair{B(4, o), B(5, i)}});
    }
  }
  return split;
}

NodeBlockMatrix toNodeBlocks(const SpMatRow& K) {
  if (K.rows() % 6 != 0) throw SolverError("stiffness matrix: size not a multiple of 6");
  NodeBlockMatrix B;
  B.blockRows = static_cast<int>(K.rows() / 6);
  B.start.assign(1, 0);
  std::unordered_map<std::string, int> distinct;  // a block's 36 values, bit for bit -> its index
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
      const std::string key(reinterpret_cast<const char*>(block.data()), sizeof block);
      const auto [it, added] = distinct.emplace(key, static_cast<int>(distinct.size()));
      if (added) B.values.insert(B.values.end(), block.begin(), block.end());
      B.column.push_back(c / 6);
      B.valueOf.push_back(it->second);
    }
    B.start.push_back(static_cast<int>(B.column.size()));
  }
  B.split = splitBlocks(B.values);
  if (!B.split.empty())
    for (int v : B.valueOf) B.splitAt.push_back(9 * v);
  return B;
}

}  // namespace enamel
