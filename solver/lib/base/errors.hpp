#pragma once
// The two kinds of error the model and solver throw, below every other file of the library (docs/contributing.md,
// layers): a case the solver cannot run (bad input) and a numerical failure (the run failed). The command line
// maps each to its exit status (exit_codes.hpp).
#include <stdexcept>

namespace enamel {

/// A case the scheme cannot run (a time step above the stable limit, a node without mass, an unknown
/// scheme): bad input, the message says which.
struct IntegratorError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// A numerical failure while setting up or running (a factorisation that failed, an operator without the
/// structure the scheme relies on): the run failed, the input was not refused.
struct SolverError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

}  // namespace enamel
