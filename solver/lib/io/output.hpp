#pragma once
// The result file: one self-describing HDF5 file per run (docs/solver.md, The result file). Every dataset carries its
// unit or normalisation as an attribute. The file is built in memory and written whole to `path.tmp` and renamed
// over `path` (file_io.hpp), so a reader (or a run killed half-way) never sees a half-written file and a full
// disk leaves the previous file. HDF5's 512-byte user block holds a seal: the file's size and a CRC-32 of all
// its bytes, which enamel_results checks before it reads the file.
#include <cstddef>
#include <cstdint>
#include <string>
#include <variant>
#include <vector>

#include "base/choices.hpp"
#include "simulation/simulation.hpp"

namespace enamel {

/// Where a run stands; its name (nameOf) is what /meta status, the checkpoint and the messages say.
ENAMEL_NAMED_ENUM(RunStatus, running, completed, failed, interrupted)

/// A snapshot of the damage state for the process-zone maps (Figs. 4-6, 8).
struct Frame {
  double targetDa = 0;   // the requested Delta_a / d (or -1 for the final state)
  double da = 0;
  long step = 0;
  double time = 0, appliedDisplacement = 0;
  std::vector<float> nodeDisplacement;      // N x 6
  std::vector<float> ifaceDamage;           // 1 - S/k
  std::vector<std::uint8_t> ifaceState;     // 0 elastic, 1 inelastic (process zone), 2 failed
  std::vector<std::uint8_t> beamBroken;
  std::vector<float> beamStress;            // per rod element: kernels.hpp computeStressOfBeam / sigma0; 0 deleted
};

struct RunRecord {
  std::vector<Measurement> history;
  std::vector<double> rcurveDa, rcurveJ;  // one point each time the crack advanced
  std::vector<Frame> frames;
  RunStatus status = RunStatus::running;
  std::string stopReason;                 // which criterion stopped it, or what went wrong
  double wallSeconds = 0;
  long steps = 0;
  std::vector<std::string> warnings;      // quasi-static checks that left their bounds
  double maxKineticRatio = 0;             // largest kinetic / strain energy while the crack grew
  double maxQuasiStaticRatio = 0;         // largest runner.hpp quasiStaticRatio (the warning's); not in the
                                          // checkpoint: a restart recomputes it from the history
  bool warnedBalance = false, warnedKinetic = false, warnedEdge = false;  // each warning is recorded once
  bool warnedFarFieldRod = false;
  StaticStart staticStart;                // what the static elastic start did (fraction 0: from rest)
};

Frame captureFrame(const Simulation& sim, double targetDa);

/// One column of /history: its dataset name, unit, description and the Measurement field it holds (a
/// Measurement field in units of Gamma_i is divided by it: `perGamma`).
struct HistoryColumn {
  const char* name;
  std::variant<long Measurement::*, int Measurement::*, double Measurement::*> field;
  const char* unit;
  const char* description = "";
  bool perGamma = false;
};
/// Every column of /history, in the order they are written.
const std::vector<HistoryColumn>& historyColumns();

/// Summary numbers of an R-curve (docs/model.md), normalised by Gamma_i.
struct RcurveSummary {
  double R_init = NAN, R_ss = NAN, R_m = NAN, dR_m = NAN, daMax = 0;
};
RcurveSummary summariseRcurve(const std::vector<double>& da, const std::vector<double>& RoverGamma);

/// The name of the result file of a run of this status. `result.h5` exists only for a completed run (so a
/// pipeline that counts it as done is never fooled); a run in progress or interrupted writes `result.partial.h5`,
/// a failed one leaves `result.failed.h5`.
const char* resultFileName(RunStatus status);
/// The result file of a run directory for a run of this status: dir/resultFileName(status).
std::string resultFileFor(const std::string& dir, RunStatus status);

/// The seal of a result file, at the start of HDF5's user block of kUserblockBytes: kResultMagic, the format of
/// this block (kSealFormat), the CRC-32 (file_io.hpp crc32) of the whole file with the crc field's 4 bytes read as
/// zeros, and the file's size in bytes; little-endian (x86-64), no padding. enamel_results/results.py reads the
/// layout from `enamel-dem constants` (sealFields).
inline constexpr std::size_t kUserblockBytes = 512;
inline constexpr char kResultMagic[8] = {'E', 'N', 'A', 'M', 'E', 'L', 'R', 'S'};
inline constexpr std::uint32_t kSealFormat = 1;
struct ResultSeal {
  char magic[8];
  std::uint32_t format = kSealFormat;
  std::uint32_t crc = 0;
  std::uint64_t fileBytes = 0;
};
/// One field of ResultSeal: its name, Python struct code and byte offset.
struct SealField {
  const char* name;
  const char* structCode;
  std::size_t offset, bytes;
};
/// The fields of ResultSeal in order (output.cpp checks them against the struct at compile time).
const std::vector<SealField>& sealFields();

/// Write the whole result file atomically. Throws WriteError (file_io.hpp) naming the file and its size when it
/// cannot be written (diskFull: no space or quota), std::runtime_error for an HDF5 error.
void writeResultFile(const std::string& path, const Simulation& sim, const RunRecord& rec);

}  // namespace enamel
