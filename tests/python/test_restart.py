"""Checkpoint and restart (issue "Hard cases and faults"): a run killed with SIGKILL at arbitrary moments and
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

from conftest import ROOT

CASE = ROOT / "paper_cases" / "theta30_s7.1_e10_cv0.toml"   # rods and interfaces break: deletions replay
# a small, fast variant of the ci preset; checkpoints every 0.3 s of wall time so that kills land between them
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
    whole, seconds = uninterrupted
    rng = random.Random(20261123)
    out = tmp_path / "killed"
    first = True
    kills = 0
    for attempt in range(KILLS + 20):
        extra = ["--checkpoint-every", "0.3"] + ([] if first else ["--restart"])
        p = subprocess.Popen([str(enamel), *map(str, args_for(out, *extra))], stderr=subprocess.PIPE, text=True)
        if kills < KILLS:
            time.sleep(rng.uniform(0.6, max(0.8, seconds / (KILLS + 1))))
            if p.poll() is None:
                p.send_signal(signal.SIGKILL)
                p.wait()
                if (out / "checkpoint.bin").exists():
                    kills += 1
                    first = False
                continue
        _, err = p.communicate(timeout=900)
        assert p.returncode == 0, err
        break
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
    with h5py.File(out / "result.h5", "r") as f:
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


def test_bad_checkpoints_are_refused(run, tmp_path):
    out = tmp_path / "bad"
    r = run(*args_for(out, "--restart"))
    assert r.returncode == 3 and "no checkpoint" in r.stderr, r.stderr
    out.mkdir(exist_ok=True)
    (out / "checkpoint.bin").write_bytes(b"ENAMELCK\x01\x00\x00\x00garbage")
    r = run(*args_for(out, "--restart"))
    assert r.returncode == EXIT_CHECKPOINT, r.stderr
    assert r.stderr.count("\n") == 1 and "checkpoint" in r.stderr
