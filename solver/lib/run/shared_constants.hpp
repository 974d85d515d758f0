#pragma once
// The numbers the Python side shares with the solver, as `enamel-dem constants` prints them: each is defined once
// in C++ (the exit statuses in exit_codes.hpp, the warning bounds in runner.hpp, the result file's seal and names
// in output.hpp, the adaptive loading rate's bounds in loading_rate.hpp, the choices of the case keys in
// choices.hpp) and read by enamel_results/constants.py from the binary, never from the source.
#include <string>

namespace enamel {

/// Every shared constant as one JSON object (`enamel-dem constants --json`).
std::string sharedConstantsJson();

/// The same as TOML (`enamel-dem constants`), for reading.
std::string sharedConstantsToml();

}  // namespace enamel
