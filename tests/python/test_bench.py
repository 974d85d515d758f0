"""The bench script itself (issue "Speed against error"), in its --quick mode (tiny specimens at the ci preset):
it runs, writes results.csv, cost_growth.csv, results.md and both figures, measures the reference against
itself as zero error, and computes the errors of the other variants against it. Correctness only: no
timing is asserted here (`make bench` measures)."""
import csv
import math
import os
import subprocess
import sys

from conftest import ROOT

PYTHON_BENCH = ROOT / "bench" / "run_bench.py"


def test_quick_bench_writes_its_report(enamel, tmp_path):
    env = dict(os.environ, ENAMEL_BINARY=str(enamel))
    r = subprocess.run([sys.executable, str(PYTHON_BENCH), "--quick", "--out",
                        str(tmp_path), "--runs", str(tmp_path / "runs")], capture_output=True, text=True, env=env,
                       timeout=600)
    assert r.returncode == 0, r.stderr
    rows = list(csv.DictReader(open(tmp_path / "results.csv")))
    assert [row["variant"] for row in rows] == ["paper", "lumped", "lumped rate2"]
    ref = rows[0]
    assert ref["integrator"] == "paper" and float(ref["rcurve_rel_l2"]) == 0.0 and float(ref["speedup_wall"]) == 1.0
    for row in rows:
        assert row["status"] == "completed" and row["exit_code"] == "0"
        for key in ("wall_s", "cpu_s", "steps", "dof", "dof_updates_per_s_per_core", "peak_memory_mb",
                    "rcurve_rel_l2", "R_init_rel_diff", "R_ss_rel_diff", "broken_rods_diff"):
            assert math.isfinite(float(row[key])), (row["variant"], key, row[key])
    lumped = rows[1]
    assert lumped["integrator"] == "lumped" and float(lumped["dt"]) > float(ref["dt"])
    assert float(rows[2]["rate_factor"]) == 2.0
    # the lumped scheme at the same rate is close to the reference on this tiny case (a loose check of the
    # comparison itself: a broken comparison gives nan, zero for everything, or a large number)
    assert 0 < float(lumped["rcurve_rel_l2"]) < 0.05
    cost = list(csv.DictReader(open(tmp_path / "cost_growth.csv")))
    assert {c["integrator"] for c in cost} == {"lumped", "paper"} and len(cost) == 4
    assert all(float(c["s_per_step"]) > 0 and float(c["est_run_s"]) > 0 for c in cost)
    for name in ("pareto.png", "pareto.pdf", "cost_growth.png", "cost_growth.pdf"):
        assert (tmp_path / "out" / name).stat().st_size > 1000
    md = (tmp_path / "results.md").read_text()
    assert "Fastest within the bound" in md or "No fast variant within the bound" in md
