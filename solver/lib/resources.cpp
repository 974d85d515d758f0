#include "resources.hpp"

#include <cmath>
#include <cstdio>

namespace enamel {

namespace {
constexpr double kPi = 3.14159265358979323846;
// Peak resident memory (VmHWM, /meta/peak_memory_mb) measured on 2026-12-02, theta30, 20 steps, 1 thread:
//   lumped  16 x 8 d: 748 nodes 32 MB;  40 x 20 d: 4640 nodes 59 MB;  80 x 80 d: 37136 nodes 270 MB;
//           200 x 200 d (paper preset): 231k nodes 1630 MB            -> ~6.5-7 kB per node
//   paper   40 x 20 d: 4640 nodes 65 MB;  40 x 40 d: 9284 nodes 120 MB -> 6.4 kB per node + ~52 B per node
//           per node of a slice (the Cholesky factor's fill grows with the bandwidth)
//   static_start > 0 adds the elastic stiffness's Cholesky factor (rods and interfaces; OpenBLAS): lumped
//           40 x 20 d 59 -> 130 MB, 200 x 200 d 1630 -> 7520 MB: ~14.2 kB per node + ~33 B per node of a slice
// The constants round these up by ~10%.
constexpr double kLumpedBytesPerNode = 7000;
constexpr double kPaperBytesPerNode = 6500;
constexpr double kPaperFillBytesPerNodeSliceNode = 60;
constexpr double kStaticBytesPerNode = 15600;
constexpr double kStaticFillBytesPerNodeSliceNode = 36;
constexpr double kBaseBytes = 30e6;  // the executable, libraries and the transverse-modulus block
}  // namespace

ResourceEstimate estimateResources(const CaseParams& p) {
  ResourceEstimate e;
  const double cosT = std::cos(p.theta_D * kPi / 180);
  e.slices = std::round(p.w_s_over_d / p.h_e_over_d) + 1;
  const double perSlice = 2 * p.h_s_over_d * cosT;
  e.nodes = e.slices * perSlice;
  e.dof = 6 * e.nodes;
  e.interfaces = 3 * e.nodes;
  e.memoryBytes = kBaseBytes + (p.integrator == "paper"
                                    ? e.nodes * (kPaperBytesPerNode + kPaperFillBytesPerNodeSliceNode * perSlice)
                                    : e.nodes * kLumpedBytesPerNode);
  if (p.static_start > 0) e.memoryBytes += e.nodes * (kStaticBytesPerNode + kStaticFillBytesPerNodeSliceNode * perSlice);
  return e;
}

double readProcKilobytes(const char* path, const char* key) {
  std::FILE* f = std::fopen(path, "r");
  if (!f) return NAN;
  const std::string format = std::string(key) + ": %lf kB";
  char line[256];
  double kb = NAN;
  while (std::fgets(line, sizeof line, f))
    if (std::sscanf(line, format.c_str(), &kb) == 1) break;
  std::fclose(f);
  return kb;
}

double availableMemoryBytes() { return readProcKilobytes("/proc/meminfo", "MemAvailable") * 1024; }

std::string checkMemoryFits(const CaseParams& p, double available) {
  const ResourceEstimate e = estimateResources(p);
  if (!(e.memoryBytes > available)) return "";
  char buf[512];
  std::snprintf(buf, sizeof buf,
                "the case needs about %.3g GB of memory (%.3g nodes, %.3g DOF, %.3g interfaces: w_s_over_d = %g, "
                "h_s_over_d = %g, h_e_over_d = %g, integrator %s) and %.3g GB are available",
                e.memoryBytes / 1e9, e.nodes, e.dof, e.interfaces, p.w_s_over_d, p.h_s_over_d, p.h_e_over_d,
                p.integrator.c_str(), available / 1e9);
  return buf;
}

}  // namespace enamel
