"""The numbers the Python side shares with the solver, as the solver itself prints them (`enamel-dem constants
--json`, solver/lib/run/shared_constants.cpp): each is defined once in C++ and read here from the binary that the
tests and the pipeline run (ENAMEL_BINARY, else build/enamel-dem: enamel_results.paths), once per process.

    EXIT          {name: exit status} (`EXIT["missing_file"]` = 3, ...; solver/lib/base/exit_codes.hpp)
    EXIT_MISSING  a file that is not there (a case file; the figure scripts' missing result)
    KINETIC_WARN  the kinetic/strain energy ratio above which a run is warned as not quasi-static (runner.hpp)
    BALANCE_WARN  |/history/energy_balance_error| above this at any row is warned (runner.hpp)
    RESULT_SEAL   the result file's seal in its HDF5 user block: magic, format, userblock_bytes, bytes, fields
                  (name, struct code, offset) in order (output.hpp ResultSeal)
    RESULT_FILES  {run status: its result file's name} (output.hpp resultFileName)
    LOADING_RATE  the adaptive loading rate's rule: rho_high, rho_low (the defaults of case key rate_adapt_rho_high
                  and of a quarter of it), rho_low_share, raise, lower (loading_rate.hpp)
    KEY_CHOICES   {case key: its allowed values in order} (choices.hpp)

Each name is read when first used, so importing this module needs no solver; without one (or with one too old to
have the `constants` command) the first use exits with one line saying to run `make build`.

    from enamel_results.constants import EXIT, EXIT_MISSING, KINETIC_WARN
"""
from __future__ import annotations

import functools
import json
import os
import pathlib
import subprocess

from enamel_results import paths


class SolverUnavailable(SystemExit):
    """No solver binary to read the shared constants from (a SystemExit: uncaught, it prints one line)."""


def solver_binary() -> pathlib.Path:
    """The solver the constants are read from: $ENAMEL_BINARY, else build/enamel-dem."""
    return pathlib.Path(os.environ.get("ENAMEL_BINARY") or paths.SOLVER)


@functools.lru_cache(maxsize=None)
def solver_constants(binary: pathlib.Path | None = None) -> dict:
    """`enamel-dem constants --json` of `binary` (default: solver_binary()), parsed; read once per binary."""
    binary = pathlib.Path(binary or solver_binary())
    where = f"enamel_results.constants: cannot read the solver's constants from {binary}"
    if not binary.is_file():
        raise SolverUnavailable(f"{where}: no such file; run `make build` (or set ENAMEL_BINARY to the solver)")
    try:
        r = subprocess.run([str(binary), "constants", "--json"], capture_output=True, text=True, timeout=60)
    except OSError as e:
        raise SolverUnavailable(f"{where}: {e.strerror}; run `make build`") from e
    if r.returncode != 0:
        why = (r.stderr.strip().splitlines() or [f"exit status {r.returncode}"])[-1]
        raise SolverUnavailable(f"{where}: {why}; run `make build` to rebuild it")
    return json.loads(r.stdout)


# name here -> (key of the solver's JSON, conversion)
_NAMES = {
    "EXIT": ("exit_codes", dict),
    "KINETIC_WARN": ("kinetic_warn", float),
    "BALANCE_WARN": ("balance_warn", float),
    "RESULT_SEAL": ("result_seal", dict),
    "RESULT_FILES": ("result_files", dict),
    "LOADING_RATE": ("loading_rate", dict),
    "KEY_CHOICES": ("key_choices", dict),
}


def __getattr__(name: str):
    if name == "EXIT_MISSING":
        return __getattr__("EXIT")["missing_file"]
    if name not in _NAMES:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    key, convert = _NAMES[name]
    return convert(solver_constants()[key])


def __dir__():
    return sorted([*globals(), *_NAMES, "EXIT_MISSING"])
