#pragma once
// Checkpoints: everything a run needs to continue exactly where it was (docs/solver.md, Checkpoints and restart).
// The model, matrices and strengths are rebuilt from the case (deterministic); the checkpoint holds the
// State (including the order in which rod elements were deleted, so that K and M are rebuilt bit for bit),
// the reactions and the run record so far. Written whole to `path.tmp` and renamed over `path`, so a run
// killed at any moment leaves the previous complete checkpoint. Binary, for this build only: the header
// carries a format version, the build that wrote it
// (buildFingerprint) and the effective case, and a mismatch is refused with a message. The file ends with a
// CRC-32 of every byte before it, checked before anything is read into the state: a file damaged on the disk,
// by a partial copy or a network file system is refused (CheckpointDamaged), never continued.
#include <string>

#include "io/output.hpp"
#include "simulation/simulation.hpp"

namespace enamel {

struct CheckpointError : std::runtime_error {
  using std::runtime_error::runtime_error;
};
/// The file is not the one a run wrote (checksum, trailer or header wrong): refused, never restarted over
/// silently; the message says to delete it to start from step 0.
struct CheckpointDamaged : CheckpointError {
  using CheckpointError::CheckpointError;
};

/// What identifies this build in a checkpoint: the solver's git hash and a hash of the executable's bytes.
/// A checkpoint is continued only by the build that wrote it (a rebuilt solver may round differently).
const std::string& buildFingerprint();

/// Throw CheckpointError (saying why) unless `path` is a checkpoint of this format, written by this build
/// for this effective case (its result-changing keys): what --resume asks before it continues a run. Reads the
/// header and checks the checksum over the whole file (CheckpointDamaged when it does not match).
void checkCheckpoint(const std::string& path, const CaseParams& params);

/// Write sim.state (reactions included) and rec to `path` atomically. Throws WriteError (file_io.hpp) naming
/// the file and its size when it cannot be written (diskFull: no space or quota).
void writeCheckpoint(const std::string& path, const Simulation& sim, const RunRecord& rec);

/// Restore a checkpoint written by writeCheckpoint for the same effective case into a freshly built sim
/// (state, deleted rod elements replayed on K and M, integrator updated) and rec. Throws CheckpointError when
/// the file is missing, of another format version, or written for a different case, and CheckpointDamaged
/// when it is truncated or its checksum does not match.
void readCheckpoint(const std::string& path, Simulation& sim, RunRecord& rec);

}  // namespace enamel
