"""research/bench_experiments/check_100: the static start against the start from rest at 100 x 100 d."""
import subprocess
import sys

from conftest import ROOT


def test_check_100_report_regenerates_from_its_records(tmp_path):
    """research/bench_experiments/check_100: the report and the figure come from the committed records alone (the runs
    are not kept), and it reads the records' R-curves, not a stored verdict: a static-start curve raised by 3%
    is reported outside the 2% bound."""
    import json
    import shutil
    src = ROOT / "research" / "bench_experiments" / "check_100"
    for name in ("rest", "static"):
        shutil.copy(src / f"record_{name}.json", tmp_path)
    run = lambda: subprocess.run([sys.executable, "-m", "research.bench_experiments.check_100.compare", "--out", str(tmp_path)],
                                 capture_output=True, text=True, cwd=ROOT, timeout=120)
    r = run()
    assert r.returncode == 0, r.stderr
    assert "(bound 0.02: within)" in r.stdout and (tmp_path / "rcurves.png").stat().st_size > 1000
    record = json.loads((tmp_path / "record_static.json").read_text())
    record["R"] = [1.03 * x for x in record["R"]]
    (tmp_path / "record_static.json").write_text(json.dumps(record))
    r = run()
    assert r.returncode == 0, r.stderr
    assert "(bound 0.02: OUTSIDE)" in r.stdout
