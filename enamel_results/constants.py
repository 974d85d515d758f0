"""The numbers the Python side shares with the solver, read from the solver's own source so that they are defined
once: the exit statuses (solver/lib/exit_codes.hpp, `EXIT["missing_file"]` = 3, ...) and the kinetic/strain
energy ratio above which a run is warned as not quasi-static (`KINETIC_WARN`, solver/lib/runner.cpp
kKineticWarn) and the energy balance error's warning bound (`BALANCE_WARN`, kBalanceWarn). Standard library only; an import fails with the file and the name when the source lacks one.

    from enamel_results.constants import EXIT, EXIT_MISSING, KINETIC_WARN
"""
from __future__ import annotations

import re

from enamel_results import paths

SOLVER_LIB = paths.ROOT / "solver" / "lib"


def _read(file: str, pattern: str, what: str) -> list[tuple[str, str]]:
    path = SOLVER_LIB / file
    found = re.findall(pattern, path.read_text())
    if not found:
        raise ImportError(f"enamel_results.constants: {path} defines no {what}")
    return found


# `constexpr int name = value;` inside namespace enamel::exit_code
EXIT: dict[str, int] = {name: int(value) for name, value in
                        _read("exit_codes.hpp", r"constexpr int (\w+) = (\d+);", "exit codes")}
EXIT_MISSING = EXIT["missing_file"]  # a file that is not there (a case file; the figure scripts' missing result)
KINETIC_WARN = float(_read("runner.cpp", r"constexpr double (kKineticWarn) = ([0-9.eE+-]+);", "kKineticWarn")[0][1])
# |/history/energy_balance_error| above this at any row is warned (solver/lib/runner.cpp kBalanceWarn)
BALANCE_WARN = float(_read("runner.cpp", r"constexpr double (kBalanceWarn) = ([0-9.eE+-]+);", "kBalanceWarn")[0][1])
