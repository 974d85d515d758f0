#pragma once
// The lumped step's node rows (lumped.cpp, docs/solver.md): per node of a slice K_I q_n, K q_n and K v_{n-1/2} from
// the node blocks (node_blocks.hpp), then v_{n+1/2} and q_{n+1}; compiled for three CPUs (node_rows.cpp). Plain
// data and the functions over it.
#include <cstdint>
#include <string>
#include <vector>

#include "data/state.hpp"
#include "kernels/node_blocks.hpp"

namespace enamel {

// The constants of a step's velocity update.
struct NodeStep {
  double keep, scale, dt, b, Vgrip;  // 1 - a dt/2, 1 + a dt/2, dt, b', V(t_n + dt/2)
  double move;                       // dt where the pass moves q (rod_damping capped); 0 where the rods' damping
                                     // solve moves it after the pass (implicit: q_{n+1} = q_n there)
};

// A slice's share of the damping work's two sums, and of the position update's maxima (pairs).
struct SliceSums {
  DoublePair workM = {0, 0}, workK = {0, 0};  // the even DOFs' sums, the odd DOFs'
  DoublePair largestStep = {0, 0}, largestValue = {0, 0};
};

// The six masses and inverse masses of a node (equal to the lumped mass and its inverse there), as pairs: they take
// a few distinct values (a node's rod elements and their spans decide them), kept once each and found by
// NodeRows::massOf.
struct NodeMass {
  DoublePair mass[3], invMass[3];
};

// What the node rows read, and the grips' residuals they write.
struct NodeRows {
  NodeBlockMatrix K;                 // ops.K in node blocks, for the fused product
  NodeBlockMatrix KI;                // the elastic interfaces' stiffness K_I in node blocks (kernels.hpp)
  std::vector<StoredOct> KIocts;     // KI's blocks as octs where the CPU has AVX-512 (K_I q by
                                     // multiplyInterfaceRowsAvx512); empty otherwise
  std::vector<NodeMass> masses;      // the distinct NodeMass values
  std::vector<int> massOf;           // per node: its NodeMass in masses
  std::vector<int> gripOfDof;        // index into ops.prescribedDofs; -1 for a free DOF
  std::vector<std::uint8_t> nodeHasGrip;  // per node: 1 when one of its DOFs is prescribed
  VecX gripResidual;                 // per grip DOF: its r (K q + K_I q - W + b' K v), for its reaction
};

// rows.masses and rows.massOf from the lumped mass and its inverse (6 per node).
void classifyNodeMasses(const VecX& mass, const VecX& invMass, int nodes, NodeRows& rows);

// K_I q_n for every node of slice k into KIq (three pairs per node, from the slice's first), then every node's
// v_{n+1/2} and q_{n+1}, W the wrench of its interfaces beyond their elastic force (node n's at
// W + stride (n - first node of the slice); stride 0: one wrench for all), v_{n+1/2} and q_{n+1} to vOut and qOut
// (the slice's nodes in order, from its first); the grips' r into rows.gripResidual. Returns the slice's sums.
SliceSums advanceNodesOfSlice(NodeRows& rows, const Operators& ops, const NodeStep& c, int k, const double* q,
                              const double* v, const double* W, int stride, DoublePair* KIq, double* vOut,
                              double* qOut);

// Which of advanceNodesOfSlice's clones the loader picked (the tests its resolver makes), and whether K_I q
// takes the AVX-512 rows.
std::string nodeRowsTarget(const NodeRows& rows);

}  // namespace enamel
