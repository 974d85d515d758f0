// Process exit codes of enamel-dem: one per class of failure, so that scripts and tests can tell
// a bad case file from a crashed run without parsing messages. The one definition: the Python side reads
// this file (enamel_results/constants.py EXIT), so keep one `constexpr int name = value;` per line.
#pragma once

namespace enamel::exit_code {

constexpr int ok = 0;                 // run finished (or command succeeded)
constexpr int usage = 2;              // bad command line: unknown option, '--set' without '=', unknown preset
constexpr int missing_file = 3;       // case file (or another input file) cannot be opened or read
constexpr int malformed_toml = 4;     // case file is not valid TOML (syntax error, duplicate key)
constexpr int unknown_key = 5;        // the set of keys is wrong: unknown key, nested table, missing required key
constexpr int wrong_type = 6;         // a key's value has the wrong TOML type (string for a number, ...)
constexpr int out_of_range = 7;       // a value outside its allowed range, not finite, or violating a cross-key rule
constexpr int output_unwritable = 8;  // output directory or result file cannot be created or written
constexpr int output_exists = 9;      // result file already exists and overwriting was not requested
constexpr int run_unstable = 10;      // run diverged: non-finite state, energy balance or kinetic ratio out of bounds
constexpr int run_failed = 11;        // run stopped on another internal error (solver factorisation, ...)
constexpr int interrupted = 12;       // run stopped by a signal (SIGINT/SIGTERM); a checkpoint remains for --restart
constexpr int checkpoint_invalid = 13;  // --restart: the checkpoint is of another version, build or case
constexpr int checkpoint_damaged = 14;  // the checkpoint's checksum or structure is wrong: delete it to start over
constexpr int disk_full = 15;           // a checkpoint or result file did not fit: no space left, quota, file size
constexpr int result_damaged = 16;      // (Python readers) a result file is truncated or fails its checksum
constexpr int output_locked = 17;       // another live run holds the output directory's lock (DIR/.lock): refused

}  // namespace enamel::exit_code
