// Process exit codes of enamel-dem: one per class of failure, so that scripts and tests can tell
// a bad case file from a crashed run without parsing messages. The one definition: `enamel-dem constants`
// prints them (kExitCodes) and the Python side reads them from there (enamel_results/constants.py EXIT).
#pragma once

namespace enamel::exit_code {

// X(name, value, meaning)
#define ENAMEL_EXIT_CODES(X)                                                                                    \
  X(ok, 0, "run finished (or command succeeded)")                                                               \
  X(usage, 2, "bad command line: unknown option, '--set' without '=', unknown preset")                          \
  X(missing_file, 3, "case file (or another input file) cannot be opened or read")                              \
  X(malformed_toml, 4, "case file is not valid TOML (syntax error, duplicate key)")                             \
  X(unknown_key, 5, "the set of keys is wrong: unknown key, nested table, missing required key")                \
  X(wrong_type, 6, "a key's value has the wrong TOML type (string for a number, ...)")                          \
  X(out_of_range, 7, "a value outside its allowed range, not finite, or violating a cross-key rule")            \
  X(output_unwritable, 8, "output directory or result file cannot be created or written")                       \
  X(output_exists, 9, "result file already exists and overwriting was not requested")                          \
  X(run_unstable, 10, "run diverged: non-finite state, energy balance or kinetic ratio out of bounds")          \
  X(run_failed, 11, "run stopped on another internal error (solver factorisation, ...)")                        \
  X(interrupted, 12, "run stopped by a signal (SIGINT/SIGTERM); a checkpoint remains for --restart")            \
  X(checkpoint_invalid, 13, "--restart: the checkpoint is of another version, build or case")                   \
  X(checkpoint_damaged, 14, "the checkpoint's checksum or structure is wrong: delete it to start over")         \
  X(disk_full, 15, "a checkpoint or result file did not fit: no space left, quota, file size")                  \
  X(result_damaged, 16, "(Python readers) a result file is truncated or fails its checksum")                    \
  X(output_locked, 17, "another live run holds the output directory's lock (DIR/.lock): refused")

#define ENAMEL_EXIT_CODE_CONSTANT(name, value, meaning) constexpr int name = value;
ENAMEL_EXIT_CODES(ENAMEL_EXIT_CODE_CONSTANT)
#undef ENAMEL_EXIT_CODE_CONSTANT

// Every exit code as data, in the order above.
struct ExitCode {
  const char* name;
  int value;
  const char* meaning;
};
#define ENAMEL_EXIT_CODE_ROW(name, value, meaning) ExitCode{#name, value, meaning},
inline constexpr ExitCode kExitCodes[] = {ENAMEL_EXIT_CODES(ENAMEL_EXIT_CODE_ROW)};
#undef ENAMEL_EXIT_CODE_ROW

}  // namespace enamel::exit_code
