"""Shared fixtures: the solver binary (ENAMEL_BINARY, set by `make test`), the small test cases, and the runs
that several modules read, each made once per pytest run (ci_run, tiny_run)."""
import os
import pathlib
import signal
import subprocess
import time

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]
CASES = ROOT / "tests" / "cases"
PAPER_CASES = ROOT / "paper_cases"
# A tiny variant of the ci preset (8 d x 4 d, stopped at Delta_a/d = 1.5, two frames; 2-10 s a case).
TINY_SETS = ["w_s_over_d=8", "h_s_over_d=4", "stop_da_over_d=1.5", "frames_da_over_d=[0.5, 1.5]"]


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


class SharedRuns:
    """Runs of paper cases at the ci preset (with `sets` on top), each made the first time a test asks for it and
    shared by every module after: runs(case) -> ROOT_DIR/ci/<case>/result.h5 (the layout of runs/, so figure
    scripts read them with --runs ROOT_DIR --preset ci)."""

    def __init__(self, run, root: pathlib.Path, sets: list):
        self.run, self.root, self.sets, self.made = run, root, sets, {}

    def __call__(self, case: str) -> pathlib.Path:
        if case not in self.made:
            out = self.root / "ci" / case
            args = ["run", PAPER_CASES / f"{case}.toml", "--preset", "ci", "--out", out, "--quiet"]
            for s in self.sets:
                args += ["--set", s]
            r = self.run(*args, timeout=900)
            assert r.returncode == 0, f"{case}: exit {r.returncode}\n{r.stderr}"
            self.made[case] = out / "result.h5"
        return self.made[case]


@pytest.fixture(scope="session")
def ci_run(run, tmp_path_factory):
    """ci_run(case): the paper case at the ci preset, run once per pytest run (the reference, reference-solver and
    hard-case tests share theta0_s21.4_e10_cv0 and theta30_s21.4_e10_cv0)."""
    return SharedRuns(run, tmp_path_factory.mktemp("ci_runs"), [])


@pytest.fixture(scope="session")
def tiny_run(run, tmp_path_factory):
    """tiny_run(case): the paper case at the tiny ci variant TINY_SETS, run once per pytest run (figures and VTK
    export tests); tiny_run.root is the runs/ root of all of them."""
    return SharedRuns(run, tmp_path_factory.mktemp("tiny_runs"), TINY_SETS)


def checkpoint_stamp(out):
    """The checkpoint's modification time (ns) in run directory `out`, or None while there is none."""
    try:
        return (pathlib.Path(out) / "checkpoint.bin").stat().st_mtime_ns
    except FileNotFoundError:
        return None


def run_with_kills(enamel, out, args, delays, timeout=900, every=0.1):
    """Run enamel-dem to completion in `out`, killed with SIGKILL once per entry of `delays`: each piece is killed
    `delay` s after it wrote a checkpoint of its own (so every kill lands between checkpoints whatever the
    machine's speed), and the next piece continues it with --restart. args(extra) gives the solver's arguments
    with `extra` (the checkpoint interval `every` s, --restart) appended. Returns the number of kills that landed (fewer
    than len(delays) when a piece finished first)."""
    kills = 0
    for delay in list(delays) + [None]:
        before = checkpoint_stamp(out)
        extra = ["--checkpoint-every", str(every)] + (["--restart"] if kills else [])
        p = subprocess.Popen([str(enamel), *map(str, args(extra))], stderr=subprocess.PIPE, text=True)
        if delay is not None:
            while p.poll() is None and checkpoint_stamp(out) in (None, before):
                time.sleep(0.005)
            time.sleep(delay)
            if p.poll() is None:
                p.send_signal(signal.SIGKILL)
                p.wait()
                kills += 1
                continue
        _, err = p.communicate(timeout=timeout)
        assert p.returncode == 0, err
        return kills
    return kills
