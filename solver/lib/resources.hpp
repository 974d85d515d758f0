#pragma once
// What a case will need before anything is built: counts of the model from the case keys alone, and the
// memory of a run from them (a case that cannot fit is refused with the
// memory needed and the memory available, before anything is allocated or written; cluster jobs ask for it).
#include <string>

#include "case_params.hpp"

namespace enamel {

/// Counts of the model a case builds, from the geometry's own rules (docs/model.md), in double precision
/// so that an absurd case (h_e = 1e-9 d, a 2000 d specimen) gives a large number instead of an overflow.
struct ResourceEstimate {
  double slices = 0;       // w_s / h_e + 1
  double nodes = 0;        // slices x rods crossing a slice (2 plies x h_s cos theta / d)
  double dof = 0;          // 6 per node
  double interfaces = 0;   // about 3 per node (6 Voronoi neighbours, each shared)
  double memoryBytes = 0;  // peak resident memory of a run
};

/// Estimate from the case keys. Memory: bytes per node measured (VmHWM) at two sizes per integrator
/// (resources.cpp gives the measurements); the `paper` scheme adds its Cholesky factor, whose fill grows with
/// the nodes of a slice (the bandwidth). Within ~10% of the measured peaks, on the high side.
ResourceEstimate estimateResources(const CaseParams& p);

/// The value in kB of the line "KEY: N kB" of a /proc file such as /proc/meminfo or /proc/self/status (NaN
/// where there is no such file or line).
double readProcKilobytes(const char* path, const char* key);

/// MemAvailable of /proc/meminfo in bytes (NaN where there is none).
double availableMemoryBytes();

/// Empty when the case fits in `available` bytes; otherwise one line saying the memory needed (and the
/// counts behind it) and the memory available.
std::string checkMemoryFits(const CaseParams& p, double available);

}  // namespace enamel
