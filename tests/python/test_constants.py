"""The numbers shared with the solver come from the solver (`enamel-dem constants --json`, read by
enamel_results.constants) and mean what the solver does: its exit statuses are the ones a run returns, the result
seal the Python side writes is the solver's byte for byte, the result file names are the pipeline's, the choices
are those the parser takes; without a solver the first use says in one line to run `make build`."""
import json
import os
import shutil
import subprocess
import sys
import tomllib

import pytest

from conftest import ROOT
from enamel_results import constants, paths, results


@pytest.fixture(scope="module")
def printed(run):
    """The solver's constants as JSON and as TOML."""
    as_json, as_toml = run("constants", "--json"), run("constants")
    assert as_json.returncode == 0 and as_toml.returncode == 0, as_json.stderr + as_toml.stderr
    return json.loads(as_json.stdout), tomllib.loads(as_toml.stdout)


def test_constants_are_the_solvers(printed, enamel):
    from_json, from_toml = printed
    # TOML prints every real to 17 digits: the JSON's reals are the same doubles, nothing rounded on the way
    assert from_json == from_toml
    assert constants.solver_constants(enamel) == from_json
    assert constants.EXIT == from_json["exit_codes"] and constants.EXIT_MISSING == from_json["exit_codes"]["missing_file"]
    assert constants.KINETIC_WARN == from_json["kinetic_warn"] and constants.BALANCE_WARN == from_json["balance_warn"]
    assert results.EXIT_CODES == constants.EXIT and results.EXIT_DAMAGED == constants.EXIT["result_damaged"]
    assert len(constants.EXIT) >= 17 and len(set(constants.EXIT.values())) == len(constants.EXIT)
    assert constants.LOADING_RATE["rho_low"] < constants.LOADING_RATE["rho_high"] < constants.KINETIC_WARN
    with pytest.raises(AttributeError):
        constants.NO_SUCH_CONSTANT


@pytest.mark.parametrize("name, args", [
    ("missing_file", ["info", "no/such/case.toml"]),
    ("malformed_toml", ["info", "{malformed}"]),
    ("unknown_key", ["info", "{case}", "--set", "no_such_key=1"]),
    ("wrong_type", ["info", "{case}", "--set", "theta_D=\"x\""]),
    ("out_of_range", ["info", "{case}", "--set", "integrator=leapfrog"]),
    ("usage", ["info", "{case}", "--preset", "no_such_preset"]),
])
def test_a_runs_exit_status_is_the_one_named(run, tmp_path, name, args):
    case = ROOT / "paper_cases" / "theta30_s21.4_e10_cv0.toml"
    malformed = tmp_path / "malformed.toml"
    malformed.write_text("theta_D = = 30\n")
    r = run(*[a.format(case=case, malformed=malformed) for a in args])
    assert r.returncode == constants.EXIT[name], f"{name}: exit {r.returncode}: {r.stderr}"
    assert len(r.stderr.strip().splitlines()) == 1, r.stderr


def test_the_seal_python_writes_is_the_solvers(tiny_run, tmp_path):
    solver_written = tiny_run("theta30_s21.4_e10_cv0")
    seal = results.seal_layout()
    data = solver_written.read_bytes()
    magic, fmt, crc, size = seal.struct.unpack_from(data)
    assert (magic, fmt, size) == (seal.magic, seal.format, len(data))
    assert seal.struct.size == constants.RESULT_SEAL["bytes"] <= seal.userblock_bytes
    results.verify_result_file(solver_written)
    copy = tmp_path / "result.h5"
    shutil.copy(solver_written, copy)
    results.seal_result_file(copy)  # nothing edited: the same seal, byte for byte
    assert copy.read_bytes() == data
    damaged = bytearray(data)
    damaged[seal.crc_offset] ^= 1
    copy.write_bytes(bytes(damaged))
    with pytest.raises(results.DamagedResult, match="checksum"):
        results.verify_result_file(copy)


def test_result_file_names_and_choices_are_the_solvers(run):
    files = constants.RESULT_FILES
    assert set(files) == {"running", "completed", "failed", "interrupted"}
    assert paths.RESULT_NAMES == {"completed": files["completed"], "partial": files["running"],
                                  "failed": files["failed"]}
    assert files["interrupted"] == files["running"]
    keys = run("keys").stdout
    for key, names in constants.KEY_CHOICES.items():
        row = next(line for line in keys.splitlines() if line.startswith(f"| `{key}` |"))
        assert "one of " + ", ".join(f'"{n}"' for n in names) in row, row
    assert constants.KEY_CHOICES["integrator"] == ["paper", "lumped"]


def without_solver(binary: str) -> subprocess.CompletedProcess:
    code = "from enamel_results.constants import EXIT_MISSING; print(EXIT_MISSING)"
    return subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT, timeout=60,
                          env=dict(os.environ, ENAMEL_BINARY=binary))


def test_without_a_solver_the_first_use_says_to_build_it(tmp_path):
    missing = without_solver(str(tmp_path / "enamel-dem"))
    old = tmp_path / "old-enamel-dem"   # a solver without the constants command
    old.write_text("#!/bin/sh\necho \"error: The following argument was not expected: $1\" >&2\nexit 2\n")
    old.chmod(0o755)
    too_old = without_solver(str(old))
    for r, why in ((missing, "no such file"), (too_old, "not expected: constants")):
        lines = r.stderr.strip().splitlines()
        assert r.returncode == 1 and not r.stdout and len(lines) == 1, r.stderr
        assert "run `make build`" in lines[0] and why in lines[0], lines[0]
    # importing the module alone needs no solver
    r = subprocess.run([sys.executable, "-c", "import enamel_results.constants"], capture_output=True, text=True,
                       cwd=ROOT, timeout=60, env=dict(os.environ, ENAMEL_BINARY=str(tmp_path / "none")))
    assert r.returncode == 0, r.stderr
