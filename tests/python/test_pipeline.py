"""The pipeline survives being killed: after SIGKILL of make's whole process
group in the middle of a run, there is no result.h5 (so nothing counts the unfinished run as done), and the next
`make` continues that run from its checkpoint to the same result, bit for bit, as an uninterrupted run."""
import os
import random
import signal
import subprocess
import time

import h5py
import numpy as np

from conftest import ROOT

CASE = "theta30_s7.1_e10_cv0"   # rods and interfaces break: deletions are replayed on resume
# a small, fast variant of the ci preset (about 2 s of stepping), one thread so results are comparable
SETS = "w_s_over_d=12 h_s_over_d=6 stop_da_over_d=3 threads=1"


# a make of its own, not a sub-make of `make test` (whose command-line variables would reach it via MAKEFLAGS)
ENV = {k: v for k, v in os.environ.items() if k not in ("MAKEFLAGS", "MFLAGS", "MAKELEVEL")}


def make(enamel, runs):
    target = runs / "ci" / CASE / "result.h5"
    cmd = ["make", "--no-print-directory", f"RUNS={runs}", "PRESET=ci", f"ENAMEL={enamel}", f"RUN_SET={SETS}",
           "CHECKPOINT_EVERY=0.1", str(target)]
    return cmd, target


def datasets(path):
    """Every dataset of a result file (path -> array), and the run's step count and status."""
    out = {}
    with h5py.File(path, "r") as f:
        f.visititems(lambda name, obj: out.__setitem__(name, obj[()]) if isinstance(obj, h5py.Dataset) else None)
        return out, int(f["meta"].attrs["steps"]), f["meta"].attrs["status"]


def test_make_killed_mid_run_resumes_bit_for_bit(enamel, tmp_path):
    cmd, whole = make(enamel, tmp_path / "whole")
    r = subprocess.run(cmd, cwd=ROOT, env=ENV, capture_output=True, text=True, timeout=600)
    assert r.returncode == 0, r.stdout + r.stderr

    cmd, target = make(enamel, tmp_path / "killed")
    run = target.parent
    p = subprocess.Popen(cmd, cwd=ROOT, env=ENV, stdout=subprocess.PIPE, stderr=subprocess.PIPE, start_new_session=True)
    deadline = time.time() + 300
    first = None
    while time.time() < deadline and p.poll() is None:   # wait for a checkpoint, then one more
        try:
            stamp = (run / "checkpoint.bin").stat().st_mtime_ns
        except FileNotFoundError:
            stamp = None
        if first is None:
            first = stamp
        elif stamp != first:
            break
        time.sleep(0.01)
    assert p.poll() is None, "the run ended before it could be killed"
    time.sleep(random.Random(20261202).uniform(0, 0.1))
    os.killpg(p.pid, signal.SIGKILL)   # make, its shell and the solver: no handler runs
    p.wait(timeout=60)
    assert not target.exists(), "an unfinished run left result.h5"
    assert (run / "checkpoint.bin").exists()

    r = subprocess.run(cmd, cwd=ROOT, env=ENV, capture_output=True, text=True, timeout=600)
    assert r.returncode == 0, r.stdout + r.stderr
    log = (run / "log.txt").read_text()
    assert "resuming from checkpoint at step" in log, log
    assert not (run / "checkpoint.bin").exists() and not (run / "result.partial.h5").exists()
    a, b = datasets(whole), datasets(target)
    assert a[1:] == b[1:] and a[2] == "completed"
    assert a[0].keys() == b[0].keys()
    different = [k for k in a[0] if not np.array_equal(a[0][k], b[0][k])]
    assert not different, different

    r = subprocess.run(cmd, cwd=ROOT, env=ENV, capture_output=True, text=True, timeout=120)   # done: nothing to run
    assert r.returncode == 0 and "run:" not in r.stdout, r.stdout


def test_run_set_gets_runs_and_figures_folders_of_its_own():
    """RUN_SET changes the physics, which Make does not track: without RUNS= its runs and figures go to folders
    named after it (never runs/<preset>/, where default runs would count as done), and the figure scripts read
    those runs; with RUNS= given, RUNS is kept."""
    def dry(*extra):
        r = subprocess.run(["make", "-n", "--no-print-directory", "figures-all", "PRESET=ci", "ENAMEL=/bin/true",
                            *extra], cwd=ROOT, env=ENV, capture_output=True, text=True, timeout=300)
        assert r.returncode == 0, r.stdout + r.stderr
        return r.stdout
    out = dry('RUN_SET=Gamma_k_over_sigma0sq=8 section="circle"')
    tag = "set_Gamma_k_over_sigma0sq-8_section-circle"
    assert f"--out runs/{tag}/ci/theta30_s21.4_e10_cv0 " in out
    assert "--set Gamma_k_over_sigma0sq=8 --set section=\"circle\"" in out or \
           "--set Gamma_k_over_sigma0sq=8 --set section=circle" in out, out[:2000]
    assert f"-m figures.fig4_decussation --preset ci --runs runs/{tag} --out figures/out/{tag}" in out
    assert f"-m figures.summary_table --preset ci --runs runs/{tag} --out figures/out/{tag}" in out
    assert " runs/ci/" not in out
    out = dry()
    assert "--out runs/ci/theta30_s21.4_e10_cv0 " in out
    assert "-m figures.fig4_decussation --preset ci --runs runs --out figures/out" in out
    out = dry("RUNS=/tmp/elsewhere", "RUN_SET=threads=1")
    assert "--out /tmp/elsewhere/ci/theta30_s21.4_e10_cv0 " in out and "runs/set_" not in out
