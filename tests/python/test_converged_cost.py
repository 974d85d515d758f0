"""`make bench-converged`'s script (bench/converged_cost.py): end to end on one small case at the ci preset with the
current binary as both baseline and new (stopped by SIGINT at a checkpoint, then continued; then a lever set on the
new one, judged against a reference run), and its verdict and table from crafted numbers. Correctness only: no speed is asserted (the ratio of one binary against itself is
whatever the machine gives)."""
import csv
import datetime
import json
import math
import os
import signal
import subprocess
import sys
import time

import h5py
import numpy as np
import pytest

from conftest import ROOT
from bench import converged_cost

CASE = "theta30_s21.4_e10_cv0"
# 28 x 4 d to Delta_a = 11 d: a common range over 10 d, so that same_rcurve can compare (~9 core-s a run)
SMALL = ["w_s_over_d=28", "h_s_over_d=4", "stop_da_over_d=11"]


def harness(enamel, tmp_path, *extra):
    args = [sys.executable, "-m", "bench.converged_cost", "--preset", "ci", "--cases", CASE, "--baseline-binary",
            str(enamel), "--binary", str(enamel), "--runs", str(tmp_path / "runs"), "--out", str(tmp_path)]
    for s in SMALL:
        args += ["--set-both", s]
    return [*args, *extra]


def run_dirs(tmp_path):
    return sorted((tmp_path / "runs" / "ci").glob(f"*/{CASE}"))


def pieces(d):
    return json.loads((d / "cost.json").read_text())["pieces"]


def test_stopped_continued_and_tabled(enamel, tmp_path):
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    first = subprocess.Popen(harness(enamel, tmp_path), cwd=ROOT, env=env, stdout=subprocess.PIPE,
                             stderr=subprocess.PIPE, text=True)
    t0 = time.monotonic()
    # result.partial.h5 appears once the solver has set up and handles SIGINT (before, the signal ends it with
    # nothing to keep, which a busy machine makes likely within a fixed delay)
    while (len([d for d in run_dirs(tmp_path) if (d / "result.partial.h5").exists()]) < 2
           and time.monotonic() - t0 < 120):
        time.sleep(0.2)
    time.sleep(1.0)
    first.send_signal(signal.SIGINT)           # forwarded: each solver writes its checkpoint and stops
    out, err = first.communicate(timeout=120)
    assert first.returncode == 130, (out, err)
    dirs = run_dirs(tmp_path)
    assert [d.parent.name.split("_")[0] for d in dirs] == ["baseline", "new"]
    for d in dirs:
        assert not (d / "result.h5").exists() and (d / "checkpoint.bin").exists()
        assert len(pieces(d)) == 1 and pieces(d)[0]["exit"] != 0 and pieces(d)[0]["cpu_s"] > 0
    assert not (tmp_path / "converged_cost.md").exists()

    second = subprocess.run(harness(enamel, tmp_path), cwd=ROOT, env=env, capture_output=True, text=True, timeout=300)
    assert second.returncode == 0, second.stderr
    core = {d.parent.name.split("_")[0]: sum(p["cpu_s"] for p in pieces(d)) for d in dirs}
    assert all(len(pieces(d)) == 2 and pieces(d)[1]["exit"] == 0 for d in dirs)
    rows = list(csv.DictReader(open(tmp_path / "converged_cost.csv")))
    assert len(rows) == 1
    row = rows[0]
    assert row["case"] == CASE and row["status"] == "complete"
    assert math.isclose(float(row["ratio"]), core["baseline"] / core["new"], rel_tol=1e-5)
    assert math.isclose(float(row["baseline_core_s"]), core["baseline"], rel_tol=1e-5)
    # the same binary, continued from checkpoints at different steps: the same run, bit for bit
    assert row["baseline_steps"] == row["new_steps"] and int(row["new_dof"]) > 0
    assert row["same_rcurve"] == "True" and float(row["R_mean_rel"]) == 0.0 and float(row["R_init_rel"]) == 0.0
    assert float(row["range_hi"]) >= 10 and row["baseline_pieces"] == "2" and row["new_threads"] == "1"
    assert float(row["fewer_steps"]) == 1.0
    # no adaptive rate: every step at phi = 1, so the ratio is its own bound
    assert float(row["new_unit_rate_share"]) == 1.0 and float(row["ratio_bound"]) == float(row["ratio"])
    assert math.isclose(float(row["fewer_steps"]) * float(row["cheaper_step"]), float(row["ratio"]), rel_tol=1e-4)
    md = (tmp_path / "converged_cost.md").read_text()
    assert "a `ci`-preset check, not the converged table" in md and "1 thread a run" in md
    assert f"G = {float(row['new_G']):g}" in md and f"| {CASE} |" in md
    assert row["verdict"] in ("met", f"not met: ratio {float(row['ratio']):.2f} < 3")

    again = subprocess.run(harness(enamel, tmp_path), cwd=ROOT, env=env, capture_output=True, text=True, timeout=120)
    assert again.returncode == 0 and "complete, not run again" in again.stdout
    assert all(len(pieces(d)) == 2 for d in dirs)   # a finished run is not run again
    assert row["reference_is_new"] == "True" and "Reference: the new run (no lever set)" in md

    # A "lever" on the new solver only: the reference (the same binary without it) runs once, the baseline is not
    # run again, and the R-curve is judged against the reference's, which is the first new run bit for bit.
    lever = subprocess.run(harness(enamel, tmp_path, "--set", "dt_factor=0.15"), cwd=ROOT, env=env,
                           capture_output=True, text=True, timeout=300)
    assert lever.returncode == 0, lever.stderr
    roles = sorted(d.parent.name.split("_")[0] for d in run_dirs(tmp_path))
    assert roles == ["baseline", "new", "new", "reference"]
    assert all(len(pieces(d)) == 2 for d in dirs)
    got = list(csv.DictReader(open(tmp_path / "converged_cost.csv")))[0]
    assert got["reference_is_new"] == "False" and got["reference_steps"] == row["new_steps"]
    assert float(got["R_mean_reference"]) == float(row["R_mean_new"])
    assert float(got["R_mean_baseline"]) == float(row["R_mean_baseline"])
    assert got["new_steps"] != row["new_steps"]          # dt_factor 0.15 takes more steps than the preset's
    assert math.isclose(float(got["lever_ratio"]), float(got["reference_core_s"]) / float(got["new_core_s"]),
                        rel_tol=1e-5)
    md = (tmp_path / "converged_cost.md").read_text()
    assert "--set dt_factor=0.15" in md and "Reference: solver" in md


def test_run_order_pairs_each_cases_baseline_and_new(tmp_path, enamel):
    """Case by case the baseline and then the new run (the two runs of a ratio side by side at two jobs), the
    reference's runs last."""
    variants = [v for v in converged_cost.variants_of(enamel, enamel, [], ["dt_factor=0.15"], [])
                if v.same_as is None]
    order = [(v.role, case) for v, case in converged_cost.run_order(variants, ["a", "b", "c"])]
    assert order == [("baseline", "a"), ("new", "a"), ("baseline", "b"), ("new", "b"), ("baseline", "c"),
                     ("new", "c"), ("reference", "a"), ("reference", "b"), ("reference", "c")]


@pytest.mark.parametrize("ratio, same, met", [(3.0, True, True), (7.5, True, True), (2.9, True, False),
                                              (5.0, False, False), (2.0, False, False), (math.nan, None, False)])
def test_verdict(ratio, same, met):
    ok, words = converged_cost.verdict(ratio, same)
    assert ok is met
    assert (words == "met") is met
    if not met and same is not None:
        assert (f"ratio {ratio:.2f} < 3" in words) is (ratio < 3)
        assert ("not the same R-curve" in words) is (not same)


def stamp(hour: int) -> str:
    """A UTC time as the harness writes it (header_of, the runs' starts)."""
    return datetime.datetime(2026, 12, 6, hour, 0).strftime("%Y-%m-%d %H:%M")


def crafted_row(case, b_core, n_core, same):
    ratio = b_core / n_core
    met, words = converged_cost.verdict(ratio, same, why="" if same else "R mean -2.5%")
    row = dict(case=case, status="complete", ratio=ratio, fewer_steps=2.0, cheaper_step=ratio / 2.0, met=met,
               verdict=words, range_hi=30.2, R_mean_reference=6.5, R_mean_new=6.5 * (1 if same else 0.975),
               R_mean_rel=0.0 if same else -0.025, R_init_rel=0.001, rods_reference=31, rods_new=30, rcurve_l2=0.01,
               same_rcurve=same, lever_ratio=ratio / 1.1, reference_is_new=False, R_mean_baseline=7.1,
               baseline_R_mean_rel=-0.0845)
    for role, core, steps in (("baseline", b_core, 544364), ("reference", b_core / 1.1, 544000),
                              ("new", n_core, 272182)):
        row.update({f"{role}_core_s": core, f"{role}_wall_s": core * 1.01, f"{role}_steps": steps,
                    f"{role}_dof": 222816, f"{role}_pieces": 1, f"{role}_threads": 1, f"{role}_G": 10.0,
                    f"{role}_git": "abc", f"{role}_machines": "AMD EPYC", f"{role}_started_utc": stamp(7)})
    return row


def test_unit_rate_share(tmp_path):
    """Steps in history intervals with phi = 1 at both ends over all steps; None without the column."""
    path = tmp_path / "result.h5"
    with h5py.File(path, "w") as f:
        f["history/step"] = [0, 10, 20, 30, 40, 100]
        f["history/rate_multiplier"] = [1.0, 1.0, 2.0, 2.0, 1.0, 1.0]
    assert converged_cost.unit_rate_share(path) == pytest.approx((10 + 60) / 100)
    with h5py.File(path, "w") as f:
        f["history/step"] = [0, 10, 20]
    assert converged_cost.unit_rate_share(path) is None


def test_table_from_crafted_numbers(tmp_path):
    rows = [dict(crafted_row("a", 1376.0, 1376.0 / 2.9, True), new_unit_rate_share=0.5, ratio_bound=5.8,
                 new_far_at_one=681, new_far_ringing=599, new_ringing_decay_over_a=1.077),
            crafted_row("b", 1376.0, 400.0, False),
            crafted_row("c", 1376.0, 1376.0 / 3.2, True), dict(case="d", status="incomplete", met=False,
                                                             verdict=converged_cost.verdict(math.nan, None)[1])]
    header = dict(date=stamp(8), machine="AMD EPYC, 2 cores", preset="converged", G="10", jobs=2, nice="",
                  goal=3.0, baseline="c09beab", new="build/enamel-dem", baseline_git="c09beab539e9",
                  new_git="abc", new_sets=" (no --set: its defaults)", both_sets="", reference="solver abc")
    md_path, csv_path = converged_cost.write_table(rows, header, tmp_path)
    md = md_path.read_text()
    lines = {line.split("|")[1].strip(): line for line in md.splitlines() if line.startswith("| ") and "---" not in line}
    assert "| **2.90** |" in lines["a"] and "not met: ratio 2.90 < 3" in lines["a"]
    assert "| **3.44** |" in lines["b"] and "not met: not the same R-curve (R mean -2.5%)" in lines["b"]
    assert "| **3.20** |" in lines["c"] and lines["c"].rstrip().endswith("| True | 7.1 (-8.45%) | met |")
    assert "| 50% (5.80) | 599 / 681 (1.08) |" in lines["a"] and "| n/a | n/a |" in lines["b"]
    assert "| 2.64 |" in lines["a"]           # the levers' own ratio, reference / new: (1376 / 1.1) / (1376 / 2.9)
    assert "no comparison" in lines["d"]
    assert "not the converged table" not in md and "G = 10" in md and "c09beab" in md
    got = list(csv.DictReader(open(csv_path)))
    assert [r["met"] for r in got] == ["False", "False", "True", "False"]


def test_ringing_decay_rate_is_the_mass_damping_of_a_decaying_ringing():
    """A kinetic energy that rings down as exp(-a t) between two events is measured at the rate a; a stretch shorter
    than the quiet rows is not measured."""
    a, t = 0.003, np.arange(400) * 10.0
    kinetic = np.exp(-a * t) * (1.5 + np.cos(0.05 * t))        # the energy swings between kinetic and strain
    rates = converged_cost.ringing_decay_rates(t, kinetic, np.array([5, 300, 320]))
    assert len(rates) == 1 and rates[0] == pytest.approx(a, rel=0.05)
    assert len(converged_cost.ringing_decay_rates(t, kinetic, np.array([5, 30]))) == 0


def test_ringing_holds_counts_the_rows_at_phi_one_far_from_events(tmp_path):
    """Rows after the first event at phi = 1 at both ends whose next event is more than FAR_ROWS rows ahead, split by
    rho against the rule's bounds (the case's rate_adapt_rho_high, here 0.02: low 0.005); rows before the first
    event, near an event or at phi > 1 are not counted."""
    n, far = 200, converged_cost.FAR_ROWS
    rods = np.zeros(n)
    rods[10:] = 1                       # events at rows 10 and 10 + far + 30
    rods[10 + far + 30:] = 2
    phi = np.ones(n)
    phi[100:] = 2.0                     # after row 100 no interval is at phi = 1
    kinetic = np.full(n, 0.001)         # rho 0.001 < 0.005: the forecast's
    kinetic[12:16] = 0.03               # rho 0.03 > 0.02: above the high bound (rows 11-14 end there)
    kinetic[16:20] = 0.01               # between the bounds
    path = tmp_path / "result.h5"
    with h5py.File(path, "w") as f:
        for k, v in dict(rate_multiplier=phi, time=np.arange(n) * 10.0, step=np.arange(n) * 100,
                         kinetic_energy_beyond_loading=kinetic, strain_energy_beams=np.ones(n),
                         strain_energy_interfaces=np.zeros(n), broken_rod_elements=rods,
                         failed_interfaces=np.zeros(n)).items():
            f[f"history/{k}"] = v
    with h5py.File(path, "a") as f:
        f.require_group("meta").attrs["rayleigh_a"] = 0.01
        f["meta"].attrs["case_toml"] = "rate_adapt_rho_high = 0.02\n"
    held = converged_cost.ringing_holds(path)
    # intervals i in [10, 99) at phi 1; the next event (row 80) more than 40 rows ahead for i < 40, none after 80
    expected_far = list(range(10, 40)) + list(range(80, 99))
    assert held["far"] == len(expected_far)
    assert held["above_high"] == 4 and held["ringing"] == 8     # rows 11-14 above, 15-18 between
    assert held["steps_at_one"] == 100 * (99 - 10) and held["growth_steps"] == 100 * (n - 1 - 10)
    with h5py.File(path, "a") as f:
        del f["history/rate_multiplier"]
    assert converged_cost.ringing_holds(path) is None
