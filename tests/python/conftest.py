"""Shared fixtures: the solver binary (ENAMEL_BINARY, set by `make test`) and the small test cases."""
import os
import pathlib
import subprocess

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]
CASES = ROOT / "tests" / "cases"


@pytest.fixture(scope="session")
def enamel():
    """Path of the enamel-dem binary; `make test` passes it in ENAMEL_BINARY."""
    path = pathlib.Path(os.environ.get("ENAMEL_BINARY", ROOT / "build" / "enamel-dem"))
    if not path.exists():
        pytest.fail(f"solver binary {path} not found: run `make build` (or `make test`)")
    return path


@pytest.fixture(scope="session")
def run(enamel):
    """Run enamel-dem with arguments; returns the CompletedProcess (text mode)."""
    def _run(*args, timeout=600):
        return subprocess.run([str(enamel), *map(str, args)], capture_output=True, text=True, timeout=timeout)
    return _run
