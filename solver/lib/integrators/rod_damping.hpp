#pragma once
// The rods' stiffness-proportional damping b K taken implicitly in the lumped step (lumped.cpp, docs/solver.md):
// the solve of
//     H v = rhs,   H = s M + c K,   s = 1 + a dt/2, c = dt b,
// M the lumped mass (diagonal), K the rods' stiffness. No two rods couple in K, so H is block tridiagonal along
// each rod: 6 x 6 node blocks on a chain of nodes in ascending node order (the model numbers nodes slice by slice,
// and a rod crosses each slice at most once). Its block factorisation is exact:
//     S_i = D_i - E_i S_p^-1 E_i^T,   P_i = E_i S_p^-1     (p the node before i on its rod; D_i = H_ii, E_i = H_ip)
//     forward  y_i = rhs_i - P_i y_p
//     backward v_i = S_i^-1 y_i - P_n^T v_n                 (n the node after i)
// The prescribed DOFs' rows and columns are the identity's (their v is given); what their columns couple into the
// free rows moves to the right-hand side. Rods of the same make give the same factors node for node, so each
// distinct pair (S^-1, P) is kept once (as node_blocks.hpp keeps K's blocks) and a node holds its index. Plain
// data and the functions over it; no I/O.
#include <Eigen/Dense>
#include <array>
#include <vector>

#include "data/state.hpp"

namespace enamel {

struct RodDampingSolve {
  using Mat6 = Eigen::Matrix<double, 6, 6>;
  struct Factors {
    Mat6 Sinv, P;  // S_i^-1 and P_i (zero where no node comes before)
  };
  // The rods lie in xy-planes, so H never couples (ux, uy, rz) with (uz, rx, ry) (node_blocks.hpp kRodGroups), nor
  // do its factors: each as two 3 x 3 blocks, the first group's then the second's.
  // Each 3 x 3 block a column at a time, a column a quad of doubles padded with a zero (the solve's loads): Sinv,
  // P and P^T of the first group, then of the second.
  typedef double Quad __attribute__((vector_size(32)));
  struct alignas(32) GroupFactors {
    Quad Sinv[2][3], P[2][3], PT[2][3];
  };
  static constexpr int kGroups[2][3] = {{0, 1, 5}, {2, 3, 4}};
  static constexpr int kLanes = 2;          // the rods in this many lanes, whatever the thread count
  double scale = 1, c = 0;                  // s and c of H = s M + c K
  std::vector<int> before, after;           // per node: the node before and after it on its rod (-1: none)
  std::vector<int> factorsOf;               // per node: its entry in `factors`
  std::vector<Factors> factors;             // the distinct factor pairs
  std::vector<GroupFactors> groupFactors;   // the same by groups (what the solve reads)
  std::vector<std::array<double, 6>> diag;  // per node: the diagonal of D_i (what refactorisation compares)
  VecX rhsScale;                            // per DOF: s m on a free DOF, 1 on a prescribed one
  std::vector<std::vector<int>> lanes;      // the nodes of each lane, ascending: a lane is a set of whole rods
  // The prescribed DOFs' columns in the free rows, by free row's node (CSR over nodes, nodeGripStart): the free
  // DOF, the prescribed DOF, c K(f, p)
  struct GripColumn {
    int freeDof, gripDof;
    double cK;
  };
  std::vector<GripColumn> gripColumns;
  std::vector<int> nodeGripStart;
  // Per prescribed DOF i (ops.prescribedDofs' order), its row of K: (DOF, K(p, DOF)) from gripRowStart[i]
  std::vector<int> gripRowStart, gripRowDof;
  std::vector<double> gripRowK;
};

/// Factorise H = scale M + c K for the rods of K (ops.K; mass: the lumped mass, 6 per node), the nodes split into
/// kLanes sets of whole rods (nodeRod: each node's rod) that the solve may take in parallel. Throws
/// IntegratorError when a node has two rod neighbours on one side (K is not one chain per rod), a block is not
/// positive definite, or a block couples the two groups of DOFs.
RodDampingSolve factoriseRodDamping(const SpMat& K, const VecX& mass, const std::vector<int>& prescribedDofs,
                                    const std::vector<int>& nodeRod, double scale, double c);

/// Refactorise after K changed (rod elements deleted): only the nodes whose blocks changed and those after them on
/// their rods (the forward recursion carries a change down its rod); every other node keeps its factors. Returns
/// how many nodes were refactorised.
long refactoriseRodDamping(const SpMat& K, const VecX& mass, const std::vector<int>& prescribedDofs,
                           RodDampingSolve& f);

/// v := H^-1 rhs, rhs = s M vStar on the free DOFs and vStar itself on the prescribed ones (their given velocity):
/// the v with s M v + c K v = s M vStar on every free row. visit(lane, node) runs once per node as soon as its v is
/// final (within a lane in descending node order). The lanes in parallel (OpenMP), each node in a fixed order: the
/// same bits at any thread count.
/// v := H^-1 rhs, rhs = s M vStar on the free DOFs and vStar itself on the prescribed ones (their given velocity):
/// the v with s M v + c K v = s M vStar on every free row. The lanes in parallel (OpenMP), each node in a fixed
/// order: the same bits at any thread count.
void solveRodDamping(const RodDampingSolve& f, const VecX& vStar, VecX& v);

/// (K v)_p of every prescribed DOF p (ops.prescribedDofs' order) into Kv.
void multiplyGripRows(const RodDampingSolve& f, const VecX& v, VecX& Kv);

}  // namespace enamel
