"""A run owns its output folder: the solver holds an exclusive lock on DIR/.lock for the run's whole life (flock,
docs/solver.md, One run per directory). A second run into a held folder is refused with its own exit status and
one line naming the folder and the holder's pid and host, before it writes anything; a SIGKILLed run leaves no
stale lock; --resume takes the same lock; --lock-wait waits for the holder to end."""
import hashlib
import signal
import socket
import subprocess
import time

import h5py
import pytest

from conftest import PAPER_CASES, checkpoint_stamp
from enamel_results.constants import EXIT

LONG_CASE = PAPER_CASES / "theta30_s21.4_e10_cv0.toml"    # at the ci preset: ~40 s, stopped by SIGINT here
OTHER_CASE = PAPER_CASES / "theta15_s21.4_e10_cv0.toml"
# the small, fast variant of the ci preset of tests/python/test_restart.py (about 2 s)
SMALL = ["--set", "w_s_over_d=12", "--set", "h_s_over_d=6", "--set", "stop_da_over_d=3", "--set", "threads=1"]


def solver(enamel, case, out, *extra):
    return [str(enamel), "run", str(case), "--preset", "ci", "--out", str(out), "--quiet", *map(str, extra)]


def hashes(folder):
    return {p.name: hashlib.sha256(p.read_bytes()).hexdigest() for p in sorted(folder.iterdir()) if p.is_file()}


def wait_for_lock(out, proc, timeout=120):
    """Wait until `proc` holds the lock of `out` (its pid in the lock file); fail if it ends first."""
    until = time.time() + timeout
    while time.time() < until:
        assert proc.poll() is None, f"the run ended (exit {proc.returncode}) before it was seen holding the lock"
        try:
            if (out / ".lock").read_text().startswith(f"pid {proc.pid} "):
                return
        except FileNotFoundError:
            pass
        time.sleep(0.05)
    pytest.fail(f"pid {proc.pid} did not take the lock of {out} within {timeout} s")


def check_refused(r, out, holder_pid):
    lines = r.stderr.strip().splitlines()
    assert r.returncode == EXIT["output_locked"] == 17, f"exit {r.returncode}: {r.stderr}"
    assert len(lines) == 1, r.stderr
    assert str(out) in lines[0] and f"pid {holder_pid} " in lines[0], lines[0]
    assert f"host {socket.gethostname()} " in lines[0], lines[0]


def test_a_second_run_into_a_live_runs_folder_is_refused_and_changes_nothing(enamel, tmp_path):
    out = tmp_path / "shared"
    first = subprocess.Popen(solver(enamel, LONG_CASE, out, "--checkpoint-every", 0), stderr=subprocess.PIPE,
                             text=True)
    try:
        wait_for_lock(out, first)
        while not (out / "result.partial.h5").exists():   # the first partial result, written once at the start
            assert first.poll() is None, first.stderr.read()
            time.sleep(0.05)
        before = hashes(out)
        # another case, with every permissive flag the pipeline passes: refused all the same
        second = subprocess.run(solver(enamel, OTHER_CASE, out, "--force", "--resume"), capture_output=True,
                                text=True, timeout=300)
        after = hashes(out)
        assert first.poll() is None, "the first run ended before the second was refused: the test proved nothing"
        check_refused(second, out, first.pid)
        assert after == before, "the refused run changed the first run's files"
        assert set(before) == {".lock", "result.partial.h5"}, before
    finally:
        first.send_signal(signal.SIGINT)
        _, err = first.communicate(timeout=300)
    assert first.returncode == EXIT["interrupted"], err   # the first run went on and stopped as asked
    with h5py.File(out / "result.partial.h5", "r") as f:
        assert f["meta"].attrs["case_source"].endswith(LONG_CASE.name)


def test_a_killed_runs_folder_is_reusable_at_once_and_resume_holds_the_lock(enamel, tmp_path):
    out = tmp_path / "killed"
    p = subprocess.Popen(solver(enamel, LONG_CASE, out, "--checkpoint-every", 0.1, *SMALL), stderr=subprocess.PIPE)
    while checkpoint_stamp(out) is None:
        assert p.poll() is None, f"the run ended (exit {p.returncode}) before its first checkpoint"
        time.sleep(0.02)
    p.kill()
    p.communicate(timeout=60)
    assert (out / ".lock").read_text().startswith(f"pid {p.pid} ")   # the dead holder's line stays, not its lock
    resumed = subprocess.Popen(solver(enamel, LONG_CASE, out, "--resume", "--checkpoint-every", 0.1, *SMALL),
                               stderr=subprocess.PIPE, text=True)
    try:
        wait_for_lock(out, resumed)
        intruder = subprocess.run(solver(enamel, LONG_CASE, out, "--resume", *SMALL), capture_output=True, text=True,
                                  timeout=300)
        assert resumed.poll() is None, "the resumed run ended before the intruder was refused: the test proved nothing"
        check_refused(intruder, out, resumed.pid)
    finally:
        _, err = resumed.communicate(timeout=600)
    assert resumed.returncode == 0, err
    assert "resuming from checkpoint at step" in err, err
    with h5py.File(out / "result.h5", "r") as f:
        assert f["meta"].attrs["status"] == "completed"


def test_lock_wait_waits_for_the_holder_then_runs(enamel, tmp_path):
    out = tmp_path / "queued"
    first = subprocess.Popen(solver(enamel, LONG_CASE, out, *SMALL), stderr=subprocess.PIPE, text=True)
    wait_for_lock(out, first)
    second = subprocess.Popen(solver(enamel, LONG_CASE, out, "--force", "--lock-wait", 600, *SMALL),
                              stderr=subprocess.PIPE, text=True)
    _, err = first.communicate(timeout=600)
    assert first.returncode == 0, err
    _, err2 = second.communicate(timeout=600)
    assert second.returncode == 0, err2
    assert "waiting up to 600 s" in err2 and f"pid {first.pid} " in err2, err2
    assert (out / ".lock").read_text().startswith(f"pid {second.pid} ")
