// The rods' damping b K taken implicitly in the lumped step (rod_damping.hpp): the block factorisation of
// H = s M + c K along each rod, and its solve.
#include "rod_damping.hpp"

#include <algorithm>
#include <cstring>
#include <map>
#include <sstream>

#include "errors.hpp"

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

// The prescribed DOFs' columns in the free rows (c K(f, p)) and their rows of K.
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

}  // namespace

RodDampingSolve factoriseRodDamping(const SpMat& K, const VecX& mass, const std::vector<int>& prescribedDofs,
                                    const std::vector<int>& nodeRod, double scale, double c, int lanes) {
  RodDampingSolve f;
  f.scale = scale, f.c = c;
  const int nodes = static_cast<int>(mass.size() / 6);
  f.before.assign(nodes, -1), f.after.assign(nodes, -1), f.factorsOf.assign(nodes, -1);
  f.diag.assign(nodes, std::array<double, 6>{});
  const std::vector<char> prescribed = prescribedMask(static_cast<int>(mass.size()), prescribedDofs);
  factoriseNodes(K, mass, prescribed, f, [](int, bool, bool) { return true; });
  f.rhsScale = scale * mass;
  for (int dof : prescribedDofs) f.rhsScale[dof] = 1;
  collectGripCouplings(K, prescribedDofs, prescribed, f);
  // lanes: contiguous ranges of rod numbers
  const int rods = nodeRod.empty() ? 1 : *std::max_element(nodeRod.begin(), nodeRod.end()) + 1;
  lanes = std::max(1, std::min(lanes, rods));
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
  collectGripCouplings(K, prescribedDofs, prescribed, f);
  return count;
}

void solveRodDamping(const RodDampingSolve& f, VecX& v) {
  for (const auto& g : f.gripColumns) v[g.freeDof] -= g.cK * v[g.gripDof] / f.rhsScale[g.freeDof];
  const int lanes = static_cast<int>(f.lanes.size());
#pragma omp parallel for schedule(static, 1)
  for (int lane = 0; lane < lanes; ++lane) {
    const std::vector<int>& nodes = f.lanes[lane];
    for (int node : nodes) {  // forward: y_i = rhs_i - P_i y_p
      auto y = v.segment<6>(6 * node);
      y = f.rhsScale.segment<6>(6 * node).cwiseProduct(y);
      if (f.before[node] >= 0) y.noalias() -= f.factors[f.factorsOf[node]].P * v.segment<6>(6 * f.before[node]);
    }
    for (auto it = nodes.rbegin(); it != nodes.rend(); ++it) {  // backward: v_i = S_i^-1 y_i - P_n^T v_n
      const int node = *it;
      const Vec6 y = v.segment<6>(6 * node);
      auto x = v.segment<6>(6 * node);
      x.noalias() = f.factors[f.factorsOf[node]].Sinv * y;
      if (f.after[node] >= 0)
        x.noalias() -= f.factors[f.factorsOf[f.after[node]]].P.transpose() * v.segment<6>(6 * f.after[node]);
    }
  }
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
