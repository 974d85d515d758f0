#pragma once
// The lumped step's ring of slice outputs (lumped.cpp): where each slice's v_{n+1/2} and q_{n+1} wait until no
// slice still to come reads v_{n-1/2} and q_n there. Inline: the step calls it once per slice.
#include <algorithm>
#include <cstdlib>
#include <vector>

#if defined(_OPENMP)
#include <omp.h>
#endif

#include "data/state.hpp"
#include "kernels/node_blocks.hpp"

namespace enamel {

// The largest |slice of a block's column - slice of its row| of a node-block matrix (geometry.hpp numbers
// nodes slice by slice: rods join neighbouring slices, or a few apart in a reduced far field; interfaces join
// nodes of one slice).
inline int sliceReach(const Model& m, const NodeBlockMatrix& K) {
  int reach = 0;
  for (int R = 0; R < K.blockRows; ++R)
    for (int b = K.start[R]; b < K.start[R + 1]; ++b)
      reach = std::max(reach, std::abs(m.nodeSlice[K.column[b]] - m.nodeSlice[R]));
  return reach;
}

// Where each slice's v_{n+1/2} and q_{n+1} go, for one thread's run of slices first .. last - 1 (the static
// schedule's share of the thread), and when they replace v_{n-1/2} and q_n in the state. A slice's rows read
// the slices up to sliceReach either side, so slice k's old values are read for the last time by slice
// k + reach: slice k goes to a ring of reach + 1 buffers of the thread and replaces the old values once slice
// k + reach is done (replaceBefore). The first and the last `reach` slices of the run are read by the
// neighbouring threads' runs: they go to vNext_ and qNext_ and replace the old values after the pass
// (replaceWaiting, after a barrier). Nothing else changes: each slice computes what it did with separate
// old and new vectors, bit for bit.
struct SliceOutputs {
  struct Slot {
    double *v, *q;  // the slice's first node's six entries; the others follow
  };
  const Operators& ops;
  State& s;
  int first = 0, last = 0, reach = 0;
  double *vWaiting, *qWaiting;  // state-sized: where the waiting slices go (vNext_, qNext_)
  std::vector<double> ring;     // reach + 1 slots of 12 maxNodesPerSlice doubles: v, then q
  SliceOutputs(const Operators& ops, State& s, int slices, int reach, double* vWaiting, double* qWaiting)
      : ops(ops), s(s), reach(reach), vWaiting(vWaiting), qWaiting(qWaiting) {
#if defined(_OPENMP)
    const int threads = omp_get_num_threads(), t = omp_get_thread_num();
#else
    const int threads = 1, t = 0;
#endif
    first = static_cast<int>(static_cast<long>(slices) * t / threads);
    last = static_cast<int>(static_cast<long>(slices) * (t + 1) / threads);
    ring.resize(12 * static_cast<std::size_t>(ops.maxNodesPerSlice) * (reach + 1));
  }
  bool waits(int k) const { return k < first + reach || k >= last - reach; }
  Slot slotOf(int k) {
    const int node = ops.sliceNodeStart[k];
    if (waits(k)) return {vWaiting + 6 * node, qWaiting + 6 * node};
    double* slot = ring.data() + 12 * static_cast<std::size_t>(ops.maxNodesPerSlice) * (k % (reach + 1));
    return {slot, slot + 6 * static_cast<std::size_t>(ops.maxNodesPerSlice)};
  }
  void replace(int k, const Slot& from) {
    const int node = ops.sliceNodeStart[k], count = 6 * (ops.sliceNodeStart[k + 1] - node);
    std::copy(from.v, from.v + count, s.vHalf.data() + 6 * node);
    std::copy(from.q, from.q + count, s.q.data() + 6 * node);
  }
  // once slice k is done: slice k - reach, unless it waits
  void replaceBefore(int k) {
    const int done = k - reach;
    if (done >= first && !waits(done)) replace(done, slotOf(done));
  }
  void replaceWaiting() {
    for (int k = first; k < last; ++k)
      if (waits(k)) replace(k, slotOf(k));
  }
};

}  // namespace enamel
