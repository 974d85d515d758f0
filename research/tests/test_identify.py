"""The identification study's report (research/identify/identify.py) regenerates from its committed data
alone: runs/ does not survive the machine it ran on, so every run's metrics and R-curve are kept in research/identify/data/
(README "Changes to the plan" 6) and the report must give the same rows and convergence numbers from them, with
no run folder at all. A store/load round trip on a tiny solver run checks that a run folder's row and its
committed record agree (metrics, curve to the stored digits, L2 between two runs)."""
import csv
import math
import shutil

import pytest

from conftest import PAPER_CASES, TINY_SETS
from research.identify import identify

CASE = identify.MAIN_CASE


def read_csv(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def same(a: str, b: str, rel=1e-5) -> bool:
    try:
        x, y = float(a), float(b)
    except ValueError:
        return a == b
    if math.isnan(x) or math.isnan(y):
        return math.isnan(x) and math.isnan(y)
    return math.isclose(x, y, rel_tol=rel, abs_tol=1e-12)


def test_report_regenerates_from_committed_data(tmp_path):
    data = tmp_path / "data"
    shutil.copytree(identify.DATA, data)
    before = {p.name: p.read_bytes() for p in data.iterdir() if p.is_file()}
    runs = tmp_path / "runs"
    runs.mkdir()
    out = tmp_path / "report"
    assert identify.main(["--stages", "", "--runs", str(runs), "--report-dir", str(out), "--data", str(data)]) == 0
    # reading the committed data changes none of it
    assert {p.name: p.read_bytes() for p in data.iterdir() if p.is_file()} == before

    committed = read_csv(identify.HERE / "convergence.csv")
    regenerated = read_csv(out / "convergence.csv")
    assert [r["G"] for r in regenerated] == [r["G"] for r in committed]
    for c, r in zip(committed, regenerated):
        for k in ("mesh_l2", "mesh_dRss", "size_dRss", "size_pair", "size_l2", "l2_ci_red", "l2_red_big", "largest",
                  "R_ss_largest", "status"):
            assert same(c[k], r[k]), (c["G"], k, c[k], r[k])

    # every completed run of the committed results.csv is there with the same numbers
    key = lambda r: (r["size"], r["h_e"], r["G"], r["case"])  # noqa: E731
    regen = {key(r): r for r in read_csv(out / "results.csv")}
    done = [r for r in read_csv(identify.HERE / "results.csv") if r["status"] == "completed"]
    assert done
    for r in done:
        g = regen[key(r)]
        assert g["source"] == "committed data"
        for k in ("da_max", "R_init", "R_ss", "R_m", "R_at3", "R_end", "broken_rods", "da_first_rod",
                  "xx_offset_median", "sawtooth_period", "x_breaks", "wall_s", "written"):
            assert same(r[k], g[k]), (key(r), k, r[k], g[k])
    md = (out / "results.md").read_text()
    assert "committed:" in md and "run folder:" not in md
    assert ("Selected: G =" in md) == any(c["status"] == "converged" for c in committed)


def test_store_and_load_round_trip(run, tmp_path):
    """Two tiny runs in the study's run-folder layout (G 3 and 8): the report keeps them in data/, and a report
    from data/ alone gives the same rows and the same L2 between them."""
    runs, data = tmp_path / "runs", tmp_path / "data"
    for G in (3, 8):
        d = identify.run_dir("ci", 0.3, G, CASE, runs)
        args = ["run", PAPER_CASES / f"{CASE}.toml", "--preset", "ci", "--out", d, "--quiet",
                "--set", f"Gamma_k_over_sigma0sq={G}"]
        for s in TINY_SETS:
            args += ["--set", s]
        r = run(*args, timeout=300)
        assert r.returncode == 0, r.stderr
    assert identify.main(["--stages", "", "--runs", str(runs), "--report-dir", str(tmp_path / "a"),
                          "--data", str(data)]) == 0
    assert sorted(p.name for p in data.glob("*.json")) == [f"ci_he0.3_G{G}__{CASE}.json" for G in (3, 8)]
    for p in data.glob("*.json"):
        assert p.stat().st_size < 20_000
    folder = {G: identify.metrics("ci", 0.3, G, CASE, runs) for G in (3, 8)}
    kept = {G: identify.stored("ci", 0.3, G, CASE, data) for G in (3, 8)}
    for G in (3, 8):
        f, k = folder[G], kept[G]
        assert k["source"] == "committed data" and f["source"] == "run folder"
        assert k["written"] == f["written"]
        for name in ("R_init", "R_ss", "R_m", "broken_rods", "da_max", "x_breaks"):
            assert same(str(f[name]), str(k[name]), rel=1e-12), (G, name)
        assert k["da"] == pytest.approx(f["da"], rel=1e-9) and k["R"] == pytest.approx(f["R"], rel=1e-9)
        assert (k["breaks"] is None) == (f["breaks"] is None)
    assert identify.l2(kept[3], kept[8]) == pytest.approx(identify.l2(folder[3], folder[8]), rel=1e-8)
    # the report from data/ alone: the same rows
    (tmp_path / "empty").mkdir()
    assert identify.main(["--stages", "", "--runs", str(tmp_path / "empty"), "--report-dir", str(tmp_path / "b"),
                          "--data", str(data)]) == 0
    a, b = read_csv(tmp_path / "a" / "results.csv"), read_csv(tmp_path / "b" / "results.csv")
    assert len(a) == len(b) == 2
    for ra, rb in zip(a, b):
        assert ra["source"] == "run folder" and rb["source"] == "committed data"
        for k in identify.ROW_KEYS:
            assert same(ra[k], rb[k]), (k, ra[k], rb[k])
    # a second store of the same run does not pile up "previous" records
    identify.store(folder[3], data)
    assert identify.stored("ci", 0.3, 3, CASE, data) is not None
    import json
    assert json.loads(identify.data_path("ci", 0.3, 3, CASE, data).read_text())["previous"] == []
