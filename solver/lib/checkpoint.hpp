#pragma once
// Checkpoints: everything a run needs to continue exactly where it was (issue "Hard cases and faults").
// The model, matrices and strengths are rebuilt from the case (deterministic); the checkpoint holds the
// State (including the order in which rod elements were deleted, so that K and M are rebuilt bit for bit),
// the reactions and the run record so far. Written whole to `path.tmp` and renamed over `path`, so a run
// killed at any moment leaves the previous complete checkpoint. Binary, for this build only: the header
// carries a format version, the build that wrote it
// (buildFingerprint) and the effective case, and a mismatch is refused with a message.
#include <string>

#include "output.hpp"
#include "simulation.hpp"

namespace enamel {

struct CheckpointError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// What identifies this build in a checkpoint: the solver's git hash and a hash of the executable's bytes.
/// A checkpoint is continued only by the build that wrote it (a rebuilt solver may round differently).
const std::string& buildFingerprint();

/// Throw CheckpointError (saying why) unless `path` is a checkpoint of this format, written by this build
/// for this effective case: what --resume asks before it continues a run. Reads only the header.
void checkCheckpoint(const std::string& path, const CaseParams& params);

/// Write sim.state (reactions included) and rec to `path` atomically. Throws CheckpointError naming the path.
void writeCheckpoint(const std::string& path, const Simulation& sim, const RunRecord& rec);

/// Restore a checkpoint written by writeCheckpoint for the same effective case into a freshly built sim
/// (state, deleted rod elements replayed on K and M, integrator updated) and rec. Throws CheckpointError when
/// the file is missing, truncated, of another format version, or written for a different case.
void readCheckpoint(const std::string& path, Simulation& sim, RunRecord& rec);

}  // namespace enamel
