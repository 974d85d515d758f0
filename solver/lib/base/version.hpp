#pragma once
// Provenance written to every result file and printed by --version.

namespace enamel {

/// The last commit that touched the solver (solver/, CMakeLists.txt), "-dirty" while those paths have
/// uncommitted changes, "unknown" outside git. Generated at build time by solver/git_hash.cmake.
extern const char* const kGitHash;

}  // namespace enamel
