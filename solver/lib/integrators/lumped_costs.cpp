// `lumped`'s cost estimate (schemes.hpp lumpedCosts; the scheme itself is lumped.cpp): the registry's row gives it
// to the estimates made before anything is built (simulation/resources.hpp).
#include "integrators/schemes.hpp"

namespace enamel {

// Peak resident memory (VmHWM, /meta/peak_memory_mb) measured on theta30, 20 steps, 1 thread: 16 x 8 d: 748 nodes
// 32 MB; 40 x 20 d: 4640 nodes 59 MB; 80 x 80 d: 37136 nodes 270 MB; 200 x 200 d (paper preset): 231k nodes
// 1630 MB -> ~6.5-7 kB per node; rounded up.
// Seconds per step: DOF-updates per second per core (one thread a run; CPU (user) seconds, on this project's
// development machine, AMD EPYC, AVX-512, 2 cores under other builds and runs). Whole ci runs 52-93 M (five
// cases), the whole reduced run 69 M, 2000 elastic steps at 80 x 80 d 109 M (user time less that of a 1-step
// run); on the same machine kind unloaded `make bench` measured 127 M at 40 x 20 d. 40 M allows for a slower
// core, a larger specimen (fewer cache hits) and the fracture stage's interface law.
SchemeCosts lumpedCosts(const CaseParams&, const SchemeSizes& n) {
  constexpr double kBytesPerNode = 7000;
  constexpr double kDofUpdatesPerSecond = 40e6;
  return SchemeCosts{n.nodes * kBytesPerNode, n.dof / kDofUpdatesPerSecond};
}

}  // namespace enamel
