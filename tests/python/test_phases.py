"""The phase average (enamel_results.metrics.phase_average) and `python3 -m pipeline.phases`: one case over N
phases of the crisscross lattice at the tip, R averaged at equal crack advance."""
import subprocess
import sys

import h5py
import numpy as np
import pytest

from conftest import PAPER_CASES, ROOT, TINY_SETS
from enamel_results import metrics, results
from pipeline import phases


def test_phase_average_is_the_mean_at_equal_advance_over_the_common_range():
    a = metrics.RCurve.of([0.3, 1.0, 2.0, 4.0], [2.0, 4.0, 4.0, 6.0], broken_rods=4)
    b = metrics.RCurve.of([0.5, 3.0, 5.0], [1.0, 6.0, 2.0], broken_rods=7)
    avg = metrics.phase_average([a, b], step=0.5)
    assert avg.curve.da[0] == pytest.approx(0.5) and avg.curve.da[-1] == pytest.approx(4.0)
    i = int(np.argmin(abs(avg.curve.da - 2.0)))
    ra, rb = 4.0, 1.0 + 5.0 * 1.5 / 2.5
    assert avg.curve.R[i] == pytest.approx((ra + rb) / 2)
    assert avg.low[i] == pytest.approx(min(ra, rb)) and avg.high[i] == pytest.approx(max(ra, rb))
    assert np.all(avg.low <= avg.curve.R) and np.all(avg.curve.R <= avg.high)
    assert avg.each.shape == (2, avg.curve.da.size)
    # broken rods: b ends 1 d past 4 d, so its total stands for the count up to 4 d; the mean is rounded
    assert avg.curve.broken_rods == round((4 + 7) / 2)


def test_phase_average_refuses_one_curve_and_disjoint_ranges():
    a = metrics.RCurve.of([0.3, 1.0], [2.0, 3.0])
    with pytest.raises(ValueError, match="at least two"):
        metrics.phase_average([a])
    with pytest.raises(ValueError, match="share no range"):
        metrics.phase_average([a, metrics.RCurve.of([2.0, 3.0], [2.0, 3.0])])


def test_set_tag_names_folders_like_the_makefile():
    assert phases.set_tag(["Gamma_k_over_sigma0sq=8", 'integrator="lumped"']) == \
        "Gamma_k_over_sigma0sq-8_integrator-lumped"


def test_phases_run_resume_and_report(enamel, tmp_path):
    """Two phases of a tiny case: each runs with its crisscross_phase, the report and the average are written, and
    the same command again runs nothing (the results are untouched)."""
    case = PAPER_CASES / "theta30_s21.4_e10_cv0.toml"
    args = [sys.executable, "-m", "pipeline.phases", str(case), "--preset", "ci", "--phases", "2", "--jobs", "2",
            "--runs", str(tmp_path), "--binary", str(enamel)]
    for s in TINY_SETS:
        args += ["--set", s]
    r = subprocess.run(args, capture_output=True, text=True, cwd=ROOT, timeout=600)
    assert r.returncode == 0, r.stdout + r.stderr
    root = phases.run_root(tmp_path, "ci", case, TINY_SETS)
    got = [results.load_result(phases.phase_dir(root, k, 2) / "result.h5") for k in range(2)]
    assert [g.param("crisscross_phase") for g in got] == [0.0, 0.5]
    assert "| average |" in r.stdout and (root / "phase_average.md").read_text() == r.stdout
    assert (root / "phase_average.png").stat().st_size > 1000
    rows = (root / "phase_average.csv").read_text().splitlines()
    assert rows[0] == "da_over_d,R_mean,R_low,R_high,R_phase_0/2,R_phase_1/2" and len(rows) > 2
    mtimes = [(phases.phase_dir(root, k, 2) / "result.h5").stat().st_mtime_ns for k in range(2)]
    r = subprocess.run(args, capture_output=True, text=True, cwd=ROOT, timeout=600)
    assert r.returncode == 0, r.stderr
    assert mtimes == [(phases.phase_dir(root, k, 2) / "result.h5").stat().st_mtime_ns for k in range(2)]


def test_phases_refuses_setting_the_phase_itself(tmp_path):
    r = subprocess.run([sys.executable, "-m", "pipeline.phases", str(PAPER_CASES / "theta30_s21.4_e10_cv0.toml"),
                        "--set", "crisscross_phase=0.5", "--runs", str(tmp_path)], capture_output=True, text=True,
                       cwd=ROOT, timeout=60)
    assert r.returncode == 2 and "give --phases instead" in r.stderr
    assert not any(tmp_path.iterdir())


# --- --compare: setting B against the plain setting A, paired phase by phase --------------------------------------

CASE = PAPER_CASES / "theta30_s21.4_e10_cv0.toml"
HALF = ["rate_factor=0.5"]


def crafted_result(path, da, R, rods: int) -> None:
    """A sealed result file with what load_result reads: an R-curve and a broken-rod history."""
    path.parent.mkdir(parents=True, exist_ok=True)
    seal = results.seal_layout()
    with h5py.File(path, "w", userblock_size=seal.userblock_bytes) as f:
        f.create_group("meta").attrs["status"] = "completed"
        f.create_group("rcurve").attrs["da_max_over_d"] = float(da[-1])
        f["rcurve/da_over_d"], f["rcurve/R_over_Gamma"] = da, R
        f["history/da_over_d"], f["history/broken_rod_elements"] = da, np.linspace(0, rods, da.size).round()
    with open(path, "r+b") as f:
        f.write(seal.struct.pack(seal.magic, seal.format, 0, 0))
    results.seal_result_file(path)


def crafted_pairs(runs, diffs, n=4, skip_b=()):
    """Phase k of the plain setting a sawtooth at its own level; under HALF the same times 1 + diffs[k]."""
    da = np.arange(0.15, 30.5, 0.3)
    for k in range(n):
        R = 6.0 + 0.2 * k + np.mod(da + 0.5 * k, 2.0) - 1.0
        R[0] = 4.0 + 0.3 * k
        crafted_result(phases.phase_dir(phases.run_root(runs, "ci", CASE, []), k, n) / "result.h5", da, R, 30)
        if k not in skip_b:
            crafted_result(phases.phase_dir(phases.run_root(runs, "ci", CASE, HALF), k, n) / "result.h5", da,
                           R * (1 + diffs[k]), 30)
    return phases.run_root(runs, "ci", CASE, HALF)


def compare(runs, capsys, *extra):
    rc = phases.main([str(CASE), "--preset", "ci", "--phases", "4", "--runs", str(runs), "--report-only",
                      "--compare", HALF[0], *extra])
    return rc, capsys.readouterr().out


def test_compare_writes_the_paired_verdict_from_crafted_phases(enamel, tmp_path, capsys):
    """Differences of +1.1, +0.9, +1.05, +0.95 %: d = +1 % with 2 SE = 0.09 % within 2 %, so the same; compare.md has
    each pair, the mean with its SE and band, and ends with the verdict that is printed."""
    root_b = crafted_pairs(tmp_path, [0.011, 0.009, 0.0105, 0.0095])
    rc, out = compare(tmp_path, capsys)
    assert rc == 0
    md = (root_b / "compare.md").read_text()
    assert md == out and root_b.name == "theta30_s21.4_e10_cv0__rate_factor-0.5"
    rows = [line for line in md.splitlines() if line.startswith("| ") and "/4 |" in line]
    assert len(rows) == 4 and "| +1.10% |" in rows[0] and "| +0.95% |" in rows[3]
    assert "| +1.10% | 4.000 | 4.044 | +1.10% |" in rows[0]         # R_init scaled with the curve
    assert "| mean R | +1.00% |" in md and "| +0.90% to +1.10% |" in md
    assert md.splitlines()[-1].startswith("verdict: rate_factor=0.5 is the same R-curve as the plain setting at 2%")
    assert (root_b / "phase_average.md").is_file() and (root_b.parent / CASE.stem / "phase_average.md").is_file()


def test_compare_a_scattered_1_percent_is_not_shown_the_same_and_tol_widens(enamel, tmp_path, capsys):
    """Differences of +5, -3, +3.5, -1.5 %: d = +1 % is within 2 %, but with its 2 SE (3.85 %) it is not: not shown the same
    at 2 %; at 10 % it is."""
    crafted_pairs(tmp_path, [0.05, -0.03, 0.035, -0.015])
    rc, out = compare(tmp_path, capsys)
    last = out.splitlines()[-1]
    assert rc == 0 and "is NOT the same R-curve" in last and "mean R +1.00% with 2 SE = 3.85% reaches past 2%" in last
    assert "beyond 2%" not in last
    rc, out = compare(tmp_path, capsys, "--tol", "0.10")
    assert "is the same R-curve as the plain setting at 10%" in out.splitlines()[-1]


def test_compare_pairs_the_phases_completed_under_both(enamel, tmp_path, capsys):
    crafted_pairs(tmp_path, [0.0, 0.0, 0.0, 0.0], skip_b=(1,))
    rc, out = compare(tmp_path, capsys)
    assert rc == 1                                     # phase 1/4 of B did not complete
    assert "phase(s) 1/4" in out and "paired over 3 phases" in out and "is the same R-curve" in out
    assert "| 1/4 |" not in out and "| 2/4 |" in out
    root_b = crafted_pairs(tmp_path / "few", [0.0] * 4, skip_b=(0, 1, 2))
    rc, out = compare(tmp_path / "few", capsys)
    assert rc == 1 and out.splitlines()[-1].startswith("verdict: none") and "| mean R |" not in out
    assert (root_b / "compare.md").read_text() == out


@pytest.mark.parametrize("args, why", [(["--compare", "crisscross_phase=0.5"], "give --phases instead"),
                                       (["--set", "rate_factor=2", "--compare", "rate_factor=0.5"],
                                        "already given by --set"),
                                       (["--compare", "rate_factor"], "KEY=VALUE")])
def test_compare_refuses_what_it_cannot_pair(tmp_path, args, why):
    r = subprocess.run([sys.executable, "-m", "pipeline.phases", str(CASE), "--runs", str(tmp_path), *args],
                       capture_output=True, text=True, cwd=ROOT, timeout=60)
    assert r.returncode == 2 and why in r.stderr
    assert not any(tmp_path.iterdir())
