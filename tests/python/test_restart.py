"""Checkpoint and restart: a run killed with SIGKILL at arbitrary moments and
restarted with --restart each time gives the same result as an uninterrupted run, bit for bit (same thread
count); SIGINT writes a checkpoint and a readable partial result marked "interrupted"; a bad checkpoint is
refused with its own exit status."""
import random
import signal
import subprocess
import time

import h5py
import numpy as np
import pytest

from conftest import ROOT, checkpoint_stamp, run_with_kills
from enamel_results.constants import EXIT

CASE = ROOT / "paper_cases" / "theta30_s7.1_e10_cv0.toml"   # rods and interfaces break: deletions replay
# a small, fast variant of the ci preset (about 2 s); the kill test checkpoints every 0.1 s of wall time
SETS = ["w_s_over_d=12", "h_s_over_d=6", "stop_da_over_d=3", "threads=1"]
KILLS = 3                      # SIGKILLs per restart test
EXIT_INTERRUPTED, EXIT_CHECKPOINT = 12, 13


def args_for(out, *extra):
    a = ["run", CASE, "--preset", "ci", "--out", out, "--quiet"]
    for s in SETS:
        a += ["--set", s]
    return a + list(extra)


def curves(path):
    with h5py.File(path, "r") as f:
        return (f["rcurve/da_over_d"][:], f["rcurve/R_over_Gamma"][:], f["history/J_over_Gamma"][:],
                f["history/broken_rod_elements"][:], int(f["meta"].attrs["steps"]), f["meta"].attrs["status"])


@pytest.fixture(scope="module")
def uninterrupted(run, tmp_path_factory):
    out = tmp_path_factory.mktemp("whole")
    t0 = time.time()
    r = run(*args_for(out))
    assert r.returncode == 0, r.stderr
    return out / "result.h5", time.time() - t0


def test_sigkill_and_restart_gives_identical_rcurve(enamel, uninterrupted, tmp_path):
    # Each piece is killed at a random moment after it has written a checkpoint of its own, so every kill lands
    # between checkpoints whatever the machine's speed (a kill timed by wall clock alone outran a 1.7 s run).
    whole, _ = uninterrupted
    rng = random.Random(20261123)
    out = tmp_path / "killed"
    kills = run_with_kills(enamel, out, lambda extra: args_for(out, *extra),
                           [rng.uniform(0.0, 0.15) for _ in range(KILLS)])
    assert kills == KILLS, f"only {kills} kills landed after a checkpoint (run too short?)"
    a, b = curves(whole), curves(out / "result.h5")
    assert b[5] == "completed"
    assert a[4] == b[4], f"steps {a[4]} vs {b[4]}"
    for x, y, name in zip(a[:4], b[:4], ("da", "R", "J history", "broken rods")):
        assert np.array_equal(x, y), f"{name} differs after {KILLS} kills and restarts"
    assert not (out / "checkpoint.bin").exists(), "a completed run removes its checkpoint"


def test_sigint_leaves_checkpoint_and_readable_partial_result(enamel, uninterrupted, tmp_path):
    whole, seconds = uninterrupted
    out = tmp_path / "int"
    p = subprocess.Popen([str(enamel), *map(str, args_for(out))], stderr=subprocess.PIPE, text=True)
    time.sleep(min(2.0, seconds / 2))
    p.send_signal(signal.SIGINT)
    _, err = p.communicate(timeout=300)
    assert p.returncode == EXIT_INTERRUPTED, err
    assert (out / "checkpoint.bin").exists()
    assert not (out / "result.h5").exists()   # result.h5 is only ever the file of a completed run
    with h5py.File(out / "result.partial.h5", "r") as f:
        assert f["meta"].attrs["status"] == "interrupted"
        assert "signal" in f["meta"].attrs["stop_reason"]
    # another value is another case: refused, and the checkpoint is kept
    r = subprocess.run([str(enamel), *map(str, args_for(out, "--restart", "--set", "zeta=0.3"))],
                       capture_output=True, text=True)
    assert r.returncode == EXIT_CHECKPOINT and "different case" in r.stderr, r.stderr
    assert (out / "checkpoint.bin").exists()
    # the same case by a relative path, with a --set that repeats a default, continues it
    args = [a if a != CASE else CASE.relative_to(ROOT) for a in args_for(out, "--restart", "--set", "rate_factor=1.0")]
    r = subprocess.run([str(enamel), *map(str, args)], capture_output=True, text=True, cwd=ROOT)
    assert r.returncode == 0, r.stderr
    a, b = curves(whole), curves(out / "result.h5")
    assert np.array_equal(a[1], b[1]) and a[4] == b[4]
    assert not (out / "result.partial.h5").exists() and not (out / "checkpoint.bin").exists()


def test_resume_continues_only_this_builds_checkpoint(enamel, uninterrupted, tmp_path):
    """--resume (what the pipeline passes): no checkpoint -> from step 0; a checkpoint of this build and case ->
    continued, bit for bit; one written by another build (here: the same binary with one byte appended, so its
    fingerprint differs) -> from step 0, saying why."""
    whole, seconds = uninterrupted
    other = tmp_path / "other-build"
    other.write_bytes(enamel.read_bytes() + b"\0")
    other.chmod(0o755)
    for binary, expect in ((other, "another build"), (enamel, "resuming from checkpoint at step")):
        out = tmp_path / f"run-{binary.name}"
        p = subprocess.Popen([str(binary), *map(str, args_for(out, "--checkpoint-every", "0.1"))],
                             stderr=subprocess.PIPE, text=True)
        deadline = time.time() + 300
        while checkpoint_stamp(out) is None and time.time() < deadline and p.poll() is None:
            time.sleep(0.02)
        p.send_signal(signal.SIGINT)
        p.communicate(timeout=300)
        assert p.returncode == EXIT_INTERRUPTED and (out / "checkpoint.bin").exists()
        r = subprocess.run([str(enamel), *map(str, args_for(out, "--resume"))], capture_output=True, text=True)
        assert r.returncode == 0, r.stderr
        assert expect in r.stderr, r.stderr
        a, b = curves(whole), curves(out / "result.h5")
        assert all(np.array_equal(x, y) for x, y in zip(a[:4], b[:4])) and a[4] == b[4]
    r = subprocess.run([str(enamel), *map(str, args_for(tmp_path / "fresh", "--resume"))], capture_output=True,
                       text=True)
    assert r.returncode == 0 and "starting from step 0: no checkpoint" in r.stderr, r.stderr


def test_bad_checkpoints_are_refused(run, tmp_path):
    out = tmp_path / "bad"
    r = run(*args_for(out, "--restart"))
    assert r.returncode == EXIT["missing_file"] and "no checkpoint" in r.stderr, r.stderr
    out.mkdir(exist_ok=True)
    (out / "checkpoint.bin").write_bytes(b"ENAMELCK\x01\x00\x00\x00garbage")
    r = run(*args_for(out, "--restart"))
    assert r.returncode == EXIT_CHECKPOINT, r.stderr
    assert r.stderr.count("\n") == 1 and "checkpoint" in r.stderr
