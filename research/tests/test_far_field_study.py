"""The far-field study (research/far_field): its report regenerates from the committed records, and its runs
resume and record."""

CASE = "theta30_s21.4_e10_cv0"


def test_far_field_report_regenerates_from_its_records(tmp_path):
    """research/far_field: every table line of its README comes from the committed records alone (the runs are not
    kept), and the comparison reads the records' R-curves, not a stored verdict: a reduced curve replaced by the
    full one is reported within 2%."""
    import json
    import shutil
    import subprocess
    import sys
    from conftest import ROOT
    src = ROOT / "research" / "far_field"
    for p in list(src.glob("record_*.json")) + [src / "elastic.json"]:
        shutil.copy(p, tmp_path)
    run = lambda: subprocess.run([sys.executable, "-m", "research.far_field.compare", "--out", str(tmp_path)],
                                 capture_output=True, text=True, cwd=ROOT, timeout=120)
    r = run()
    assert r.returncode == 0, r.stderr
    readme = (src / "README.md").read_text()
    for line in r.stdout.splitlines():
        assert line in readme, f"README.md of research/far_field lacks the regenerated line: {line}"
    assert "| m4_h22 |" in r.stdout and "(outside 2%)" in r.stdout
    assert (tmp_path / "rcurves.png").stat().st_size > 1000
    full = json.loads((tmp_path / "record_full.json").read_text())
    for p in tmp_path.glob("record_*.json"):
        rec = json.loads(p.read_text())
        rec["da"], rec["R"] = full["da"], full["R"]
        p.write_text(json.dumps(rec))
    r = run()
    assert r.returncode == 0, r.stderr
    assert "(outside 2%)" not in r.stdout

def test_far_field_study_runs_resume_and_record(ci_run, tmp_path):
    """`make bench-far-field` (compare --run-all): a run whose result.h5 exists is not run again but recorded (with
    its case, so each case is held against its own full model); a missing one is run with the study's variant and
    far field, and one that fails is reported and leaves no record."""
    import json
    import os
    import shutil
    import subprocess
    import sys
    from conftest import ROOT
    done = tmp_path / "runs" / "far_field" / "full"
    done.mkdir(parents=True)
    shutil.copy(ci_run(CASE), done / "result.h5")
    fake = tmp_path / "fake-enamel"
    fake.write_text("#!/bin/sh\necho \"$@\" > \"$(dirname \"$0\")/args.txt\"\nexit 10\n")
    fake.chmod(0o755)
    out = tmp_path / "report"
    out.mkdir()
    r = subprocess.run([sys.executable, "-m", "research.far_field.compare", "--run-all", str(fake), "--jobs", "1",
                        "--only", "full", "cv03_m2_h22", "--out", str(out)], capture_output=True, text=True,
                       cwd=tmp_path, env=dict(os.environ, PYTHONPATH=str(ROOT)), timeout=300)
    assert r.returncode == 1, r.stdout + r.stderr
    assert "full: done already" in r.stdout and "1 run(s) did not complete" in r.stderr
    record = json.loads((out / "record_full.json").read_text())
    assert record["case"] == CASE and record["meta"]["status"] == "completed"
    assert not (out / "record_cv03_m2_h22.json").exists()
    args = (tmp_path / "args.txt").read_text().split()
    assert "theta30_s28.5_e10_cv0.3_seed1.toml" in args[1] and "--resume" in args
    for s in ("far_field_slices=2", "full_half_height_over_d=22", "static_start=0.95", "w_s_over_d=80", "threads=1"):
        assert s in args
