"""The phase average (enamel_results.metrics.phase_average) and `python3 -m pipeline.phases`: one case over N
phases of the crisscross lattice at the tip, R averaged at equal crack advance."""
import subprocess
import sys

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
